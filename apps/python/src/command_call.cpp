// command_call.cpp: see command_call.hpp.
#include "command_call.hpp"

#include <cstdlib>
#include <limits>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>

#include "errors.hpp"
#include "json_convert.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/io/csv_reader.hpp"
#include "puncture/scene_io.hpp"

namespace py = pybind11;

namespace puncture::python {

TemporaryDirectory::TemporaryDirectory() {
  std::string pattern = (std::filesystem::temp_directory_path() / "puncture-python-XXXXXX").string();
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (::mkdtemp(buffer.data()) == nullptr) throw std::runtime_error("cannot create a temporary directory under " + pattern);
  path_ = buffer.data();
}

TemporaryDirectory::~TemporaryDirectory() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::filesystem::path write_scene_file(const Scene& scene, const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / (scene.name + ".json");
  io::write_file_atomically(path, scene_to_json_text(scene));
  return path;
}

CommandOutput run_command(const std::function<int(std::ostream&, std::ostream&)>& command, PythonCallback* callback) {
  std::ostringstream out, err;
  int code = 0;
  {
    py::gil_scoped_release release;
    code = command(out, err);
  }
  if (callback) callback->rethrow_if_raised();
  if (code != 0) raise_for_exit_code(code, err.str());
  return {out.str(), err.str()};
}

py::dict csv_file_arrays(const std::filesystem::path& path) {
  const io::CsvDocument doc = io::read_csv_file(path);
  py::module_ numpy = py::module_::import("numpy");
  py::dict columns;
  for (std::size_t c = 0; c < doc.header.size(); ++c) {
    std::vector<double> numbers;
    numbers.reserve(doc.records.size());
    bool numeric = true;
    for (const io::CsvRecord& r : doc.records) {
      double x = 0.0;
      // A column of numbers where some are "nan" (a quantity a row does not
      // have, e.g. the FEM's own build time) stays a float array with NaN.
      const bool missing = c < r.fields.size() && (r.fields[c] == "nan" || r.fields[c] == "NaN");
      if (missing) x = std::numeric_limits<double>::quiet_NaN();
      else if (c >= r.fields.size() || !io::parse_finite_number(r.fields[c], x)) {
        numeric = false;
        break;
      }
      numbers.push_back(x);
    }
    if (numeric) {
      columns[py::str(doc.header[c])] = py::array_t<double>(static_cast<py::ssize_t>(numbers.size()), numbers.data());
    } else {
      py::list text;
      for (const io::CsvRecord& r : doc.records) text.append(c < r.fields.size() ? r.fields[c] : std::string());
      columns[py::str(doc.header[c])] = numpy.attr("asarray")(text, py::arg("dtype") = "str");
    }
  }
  return columns;
}

py::object json_file(const std::filesystem::path& path) {
  return json_to_python(nlohmann::json::parse(io::read_text_file(path)));
}

py::list warning_lines(const std::string& err) {
  py::list warnings;
  std::istringstream in(err);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("warning: ", 0) == 0) warnings.append(line.substr(9));
  return warnings;
}

}  // namespace puncture::python
