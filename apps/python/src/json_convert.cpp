// json_convert.cpp: see json_convert.hpp.
#include "json_convert.hpp"

#include <cmath>
#include <sstream>

#include "errors.hpp"

namespace py = pybind11;

namespace puncture::python {

py::object json_to_python(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [key, item] : value.items()) d[py::str(key)] = json_to_python(item);
      return std::move(d);
    }
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& item : value) l.append(json_to_python(item));
      return std::move(l);
    }
    case nlohmann::json::value_t::string: return py::str(value.get<std::string>());
    case nlohmann::json::value_t::boolean: return py::bool_(value.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(value.get<long long>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(value.get<unsigned long long>());
    case nlohmann::json::value_t::number_float: return py::float_(value.get<double>());
    default: return py::none();
  }
}

namespace {

std::string type_name(py::handle value) { return py::str(py::type::handle_of(value).attr("__name__")); }

nlohmann::json number_to_json(py::handle value, const std::string& source, const std::string& path) {
  if (py::isinstance<py::int_>(value) || PyIndex_Check(value.ptr()))
    return nlohmann::json(py::cast<long long>(py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()))));
  const double x = py::cast<double>(py::reinterpret_steal<py::object>(PyNumber_Float(value.ptr())));
  if (!std::isfinite(x)) {
    std::ostringstream s;
    s << "must be a finite number (got " << x << ")";
    raise_scene_error(source, path, s.str());
  }
  return nlohmann::json(x);
}

}  // namespace

nlohmann::json python_to_json(py::handle value, const std::string& source, const std::string& path) {
  if (value.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<py::dict>(value)) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [key, item] : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(key))
        raise_scene_error(source, path, "object keys must be str (got " + type_name(key) + ")");
      const std::string k = key.cast<std::string>();
      j[k] = python_to_json(item, source, path + "/" + k);
    }
    return j;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    nlohmann::json j = nlohmann::json::array();
    std::size_t i = 0;
    for (const py::handle item : value) j.push_back(python_to_json(item, source, path + "/" + std::to_string(i++)));
    return j;
  }
  if (PyIndex_Check(value.ptr()) || PyNumber_Check(value.ptr())) {
    if (py::hasattr(value, "__index__") || py::hasattr(value, "__float__")) return number_to_json(value, source, path);
  }
  raise_scene_error(source, path, "a scene holds no value of type " + type_name(value));
}

nlohmann::json::json_pointer json_path_pointer(const std::string& path, const std::string& source) {
  std::string p = path;
  if (p == "/") p.clear();
  if (!p.empty() && p.front() != '/') p = "/" + p;
  try {
    return nlohmann::json::json_pointer(p);
  } catch (const nlohmann::json::exception& e) {
    raise_scene_error(source, path, std::string("not a JSON path: ") + e.what());
  }
}

}  // namespace puncture::python
