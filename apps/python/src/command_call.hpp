// command_call.hpp: running a command of puncture_app_lib (commands.hpp)
// from Python: the scene written to a temporary file, the GIL released while
// it runs, its stdout and stderr captured, its exit code turned into the
// module's exception (errors.hpp), its output files read back.
#pragma once

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>

#include <pybind11/pybind11.h>

#include "puncture/scene.hpp"
#include "python_progress.hpp"

namespace puncture::python {

/// A directory under the system's temporary directory, removed with
/// everything in it when the object goes.
class TemporaryDirectory {
 public:
  TemporaryDirectory();
  ~TemporaryDirectory();
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Writes `scene` as <dir>/<scene name>.json (the commands name their
/// outputs after the scene's name, not the file's) and returns the path.
std::filesystem::path write_scene_file(const Scene& scene, const std::filesystem::path& dir);

/// What a command printed.
struct CommandOutput {
  std::string out;  ///< stdout (progress, the report)
  std::string err;  ///< warnings (and errors)
};

/// Runs command(out, err) with the GIL released. A Python exception raised
/// inside through `callback` (the progress callback, Ctrl-C) is re-raised as
/// it was; otherwise a non-zero exit code raises the module's exception with
/// the command's message.
CommandOutput run_command(const std::function<int(std::ostream& out, std::ostream& err)>& command,
                          PythonCallback* callback = nullptr);

/// A CSV file of the program (`# key: value` provenance lines, a header) as
/// {column: NumPy array}: float64 where every field is a finite number, str otherwise.
pybind11::dict csv_file_arrays(const std::filesystem::path& path);

/// A JSON file as Python objects (dicts, lists, numbers, str).
pybind11::object json_file(const std::filesystem::path& path);

/// "warning: ..." lines of a command's stderr, without the prefix.
pybind11::list warning_lines(const std::string& err);

}  // namespace puncture::python
