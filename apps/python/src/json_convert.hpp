// json_convert.hpp: JSON values (nlohmann::json) to and from Python objects.
//
// To Python: objects become dicts, arrays lists, numbers int or float,
// strings str, null None. From Python: dict (str keys), list, tuple, str,
// bool, int, float, None, and anything with __index__ or __float__ (NumPy
// scalars). A float that is NaN or infinite, a non-str key, or another type
// raises puncture.SceneError naming `source` and the JSON path where it sits:
// a scene file cannot hold it either.
#pragma once

#include <string>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>

namespace puncture::python {

pybind11::object json_to_python(const nlohmann::json& value);

/// `path` is the JSON pointer of `value` within the document (for messages).
nlohmann::json python_to_json(pybind11::handle value, const std::string& source, const std::string& path = "");

/// "layers/0/thickness_mm" or "/layers/0/thickness_mm" as a JSON pointer
/// ("" or "/" is the whole document). Raises puncture.SceneError on a malformed path.
nlohmann::json::json_pointer json_path_pointer(const std::string& path, const std::string& source);

}  // namespace puncture::python
