// errors.cpp: the module's exception types (errors.hpp) and the translation
// of the C++ exceptions the bindings let through.
#include "errors.hpp"

#include <sstream>

#include "bindings.hpp"
#include "puncture/io/csv_reader.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/scene_io.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

/// The exception types, created once by bind_errors (module lifetime).
struct ErrorTypes {
  py::object input, scene, run, output;
};
ErrorTypes& types() {
  static ErrorTypes t;
  return t;
}

py::object make_type(py::module_& m, const char* name, py::handle base, const char* doc) {
  py::object type = py::reinterpret_steal<py::object>(
      PyErr_NewExceptionWithDoc((std::string("puncture.") + name).c_str(), doc, base.ptr(), nullptr));
  if (!type) throw py::error_already_set();
  m.attr(name) = type;
  return type;
}

/// The command's error lines without the "error: " each starts with.
std::string strip_error_prefix(const std::string& text) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) {
    if (line.rfind("error: ", 0) == 0) line = line.substr(7);
    else if (line.rfind("warning: ", 0) == 0) continue;
    if (line.empty()) continue;
    out += (out.empty() ? "" : "\n") + line;
  }
  return out.empty() ? text : out;
}

}  // namespace

namespace {
/// Sets puncture.SceneError with its attributes as the pending Python error.
void set_scene_error(const std::string& file, const std::string& json_path, const std::string& message) {
  py::object error = types().scene(message);
  error.attr("file") = file;
  error.attr("json_path") = json_path;
  PyErr_SetObject(types().scene.ptr(), error.ptr());
}
}  // namespace

void raise_scene_error(const std::string& file, const std::string& json_path, const std::string& message) {
  set_scene_error(file, json_path, SceneError(file, json_path, message).what());  // the reader's "file: path: what"
  throw py::error_already_set();
}

void raise_for_exit_code(int exit_code, const std::string& error_text) {
  const std::string message = strip_error_prefix(error_text);
  py::object type = exit_code == 2 ? types().input : exit_code == 3 ? types().output : types().run;
  PyErr_SetString(type.ptr(), message.c_str());
  throw py::error_already_set();
}

void bind_errors(py::module_& m) {
  ErrorTypes& t = types();
  t.input = make_type(m, "InputError", PyExc_ValueError,
                      "Bad input: a scene, a reference curve or an option (the program's exit code 2).");
  t.scene = make_type(m, "SceneError", t.input,
                      "A bad scene: the message names the file and the JSON path of the field "
                      "(attributes .file and .json_path), as the command line's.");
  t.run = make_type(m, "RunError", PyExc_RuntimeError,
                    "The run failed: a numerical failure, an FEM failure (the program's exit code 1).");
  t.output = make_type(m, "OutputError", PyExc_OSError,
                       "An output cannot be written: the message names the path (the program's exit code 3).");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const SceneError& e) {
      set_scene_error(e.file(), e.json_path(), e.what());
    } catch (const io::CsvFormatError& e) {
      PyErr_SetString(types().input.ptr(), e.what());
    } catch (const io::OutputError& e) {
      PyErr_SetString(types().output.ptr(), e.what());
    }
  });
}

}  // namespace puncture::python
