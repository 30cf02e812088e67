// scene_binding.cpp: puncture.Scene: load, save, dicts, fields by JSON path,
// always validated by the C++ reader (parse_scene), so a Scene in Python is
// one the `puncture` program accepts.
#include <filesystem>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "errors.hpp"
#include "json_convert.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/io/output_session.hpp"
#include "scene_handle.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

SceneHandle from_document(const nlohmann::json& document, const std::string& source) {
  return SceneHandle{parse_scene(document.dump(), source), source};
}

/// Sets the field at `pointer` in `document`; its parent must exist (an array
/// index at most the array's size: the size appends).
void set_field(nlohmann::json& document, const nlohmann::json::json_pointer& pointer, const nlohmann::json& value,
               const std::string& source) {
  if (pointer.empty()) {
    document = value;
    return;
  }
  const nlohmann::json::json_pointer parent = pointer.parent_pointer();
  if (!document.contains(parent) || !(document.at(parent).is_object() || document.at(parent).is_array()))
    raise_scene_error(source, pointer.to_string(), "no such field: " + (parent.empty() ? "/" : parent.to_string()) +
                                                       " is not an object or array of the scene");
  nlohmann::json& container = document.at(parent);
  if (container.is_array()) {
    const std::string token = pointer.back();
    std::size_t index = 0;
    try {
      index = std::stoul(token);
    } catch (const std::exception&) {
      raise_scene_error(source, pointer.to_string(), "not an array index: '" + token + "'");
    }
    if (index > container.size())
      raise_scene_error(source, pointer.to_string(),
                        "index " + token + " beyond the array's " + std::to_string(container.size()) + " items");
  }
  document[pointer] = value;
}

SceneHandle with_changes(const SceneHandle& s, const py::dict& changes) {
  nlohmann::json document = s.document();
  for (const auto& [key, value] : changes) {
    const std::string path = py::cast<std::string>(key);
    const auto pointer = json_path_pointer(path, s.source);
    set_field(document, pointer, python_to_json(value, s.source, pointer.to_string()), s.source);
  }
  return from_document(document, s.source);
}

/// Sets one field; the scene is unchanged when the result is not a valid scene.
void set_path(SceneHandle& s, const std::string& path, const py::object& value) {
  s = with_changes(s, py::dict(py::arg(path.c_str()) = value));
}

py::object get_field(const SceneHandle& s, const std::string& path) {
  const nlohmann::json document = s.document();
  const auto pointer = json_path_pointer(path, s.source);
  if (!document.contains(pointer)) throw py::key_error(s.source + ": " + pointer.to_string() + ": no such field in the scene");
  return json_to_python(document.at(pointer));
}

void save(const SceneHandle& s, const std::filesystem::path& path) {
  try {
    io::write_file_atomically(path, scene_to_json_text(s.scene));
  } catch (const std::runtime_error& e) {  // "cannot write '<path>': <reason>"
    throw io::OutputError(e.what());
  }
}

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<SceneHandle>(m, "Scene",
                          "A validated scene (scenes/README.md): what `puncture run` reads. Fields by JSON path "
                          "('layers/0/thickness_mm'); every change is validated by the C++ reader and raises "
                          "puncture.SceneError naming the path.")
      .def_static(
          "load", [](const std::filesystem::path& path) { return SceneHandle{load_scene(path), path.string()}; },
          py::arg("path"), "Reads and validates a scene file.")
      .def_static(
          "from_dict",
          [](const py::dict& d, const std::string& source) { return from_document(python_to_json(d, source), source); },
          py::arg("d"), py::arg("source") = "<dict>", "A scene from a dict in the file's schema; `source` names it in messages.")
      .def_static(
          "from_json", [](const std::string& text, const std::string& source) { return SceneHandle{parse_scene(text, source), source}; },
          py::arg("text"), py::arg("source") = "<json>", "A scene from JSON text.")
      .def_static(
          "default", []() { const auto p = apps::default_scene_path(); return SceneHandle{load_scene(p), p.string()}; },
          "scenes/default.json (of the working directory if present, else of the source tree).")
      .def("to_dict", [](const SceneHandle& s) { return json_to_python(s.document()); },
           "The scene as a dict in the file's schema (what save() writes).")
      .def("to_json", [](const SceneHandle& s) { return scene_to_json_text(s.scene); }, "The scene as file text.")
      .def("save", &save, py::arg("path"),
           "Writes the scene file (under a temporary name, renamed when complete).")
      .def("get", &get_field, py::arg("path"), "The field at a JSON path, e.g. 'layers/0/thickness_mm' (KeyError if absent).")
      .def(
          "set",
          &set_path,
          py::arg("path"), py::arg("value"),
          "Sets the field at a JSON path; the scene is validated and left unchanged on error (puncture.SceneError).")
      .def("__getitem__", &get_field, py::arg("path"), "scene['layers/0/thickness_mm']: get(path)")
      .def(
          "__setitem__",
          &set_path,
          py::arg("path"), py::arg("value"), "scene['layers/0/thickness_mm'] = 2.0: set(path, value)")
      .def("updated", &with_changes, py::arg("changes"),
           "A new scene with every {path: value} of `changes` set, validated once (for fields that must change together).")
      .def("copy", [](const SceneHandle& s) { return s; })
      .def_property_readonly("name", [](const SceneHandle& s) { return s.scene.name; })
      .def_property_readonly("source", [](const SceneHandle& s) { return s.source; }, "The file or '<dict>' messages name.")
      .def_property_readonly("layer_names",
                             [](const SceneHandle& s) {
                               std::vector<std::string> names;
                               for (const Layer& l : s.scene.layers) names.push_back(l.name);
                               return names;
                             })
      .def_property_readonly("haptic_rate_Hz", [](const SceneHandle& s) { return s.scene.realtime.haptic_rate_Hz; })
      .def("__eq__", [](const SceneHandle& a, const SceneHandle& b) { return scene_to_json_text(a.scene) == scene_to_json_text(b.scene); })
      .def("__repr__", [](const SceneHandle& s) {
        return "<puncture.Scene '" + s.scene.name + "' from " + s.source + ", " + std::to_string(s.scene.layers.size()) + " layers>";
      });
  m.def("default_scene_path", &apps::default_scene_path, "scenes/default.json (working directory, else the source tree).");
}

}  // namespace puncture::python
