// command_outputs.cpp: see command_outputs.hpp.
#include "command_outputs.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "command_call.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/io/output_session.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

std::vector<std::filesystem::path> files_below(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(std::filesystem::relative(entry.path(), dir));
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

py::dict read_outputs(const std::filesystem::path& dir) {
  py::dict result;
  py::list names;
  for (const std::filesystem::path& f : files_below(dir)) {
    names.append(f.string());
    if (f.has_parent_path()) continue;  // a case's report, fem/*.vtu: listed only
    const std::string ext = f.extension().string();
    const std::string key = result.contains(f.stem().string()) ? f.string() : f.stem().string();
    if (ext == ".json") result[py::str(key)] = json_file(dir / f);
    else if (ext == ".csv") result[py::str(key)] = csv_file_arrays(dir / f);
    else if (ext == ".md") result[py::str(key)] = io::read_text_file(dir / f);
  }
  result["files"] = names;
  return result;
}

void copy_outputs(const std::filesystem::path& from, const std::filesystem::path& to) {
  io::OutputSession session(to);
  for (const std::filesystem::path& f : files_below(from)) session.write_text(f.string(), io::read_text_file(from / f));
  session.commit();
}

}  // namespace puncture::python
