// reference_curve_file.cpp: see reference_curve_file.hpp.
#include "reference_curve_file.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "errors.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/io/csv_writer.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

/// One column as its CSV fields.
std::vector<std::string> column_fields(const std::string& name, const py::handle& values) {
  py::module_ numpy = py::module_::import("numpy");
  const py::array a = numpy.attr("asarray")(values).cast<py::array>();
  if (a.ndim() != 1) raise_for_exit_code(2, "reference column '" + name + "': must be one-dimensional");
  const char kind = a.dtype().attr("kind").cast<std::string>().at(0);
  std::vector<std::string> fields;
  fields.reserve(static_cast<std::size_t>(a.size()));
  if (kind == 'f' || kind == 'i' || kind == 'u') {
    for (double x : py::cast<std::vector<double>>(numpy.attr("asarray")(a, py::arg("dtype") = "float64").attr("tolist")())) {
      if (!std::isfinite(x)) raise_for_exit_code(2, "reference column '" + name + "': a value is not finite");
      fields.push_back(io::csv_number(x));
    }
  } else {
    for (const py::handle item : a.attr("tolist")()) fields.push_back(io::csv_quote(py::str(item)));
  }
  return fields;
}

}  // namespace

void write_reference_curve(const py::handle& columns, const std::filesystem::path& path) {
  std::vector<std::string> names;
  std::vector<std::vector<std::string>> fields;
  for (const py::handle key : columns.attr("keys")()) {
    names.push_back(py::str(key));
    fields.push_back(column_fields(names.back(), columns[key]));
    if (fields.back().size() != fields.front().size())
      raise_for_exit_code(2, "reference column '" + names.back() + "': " + std::to_string(fields.back().size()) +
                                 " values, column '" + names.front() + "' has " + std::to_string(fields.front().size()));
  }
  std::string text;
  for (std::size_t c = 0; c < names.size(); ++c) text += (c ? "," : "") + io::csv_quote(names[c]);
  text += '\n';
  const std::size_t rows = fields.empty() ? 0 : fields.front().size();
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < names.size(); ++c) text += (c ? "," : "") + fields[c][r];
    text += '\n';
  }
  io::write_file_atomically(path, text);
}

}  // namespace puncture::python
