// errors.hpp: the module's exceptions and how C++ errors and the commands'
// exit codes become them.
//
//   puncture.InputError(ValueError)     bad input: exit code 2 of the program
//   puncture.SceneError(InputError)     a scene field or file; .file and .json_path
//   puncture.RunError(RuntimeError)     the run failed: exit code 1
//   puncture.OutputError(OSError)       an output cannot be written: exit code 3
//
// Every message is the one the command line prints (without its "error: ").
#pragma once

#include <string>

#include <pybind11/pybind11.h>

namespace puncture::python {

/// Raises the Python exception of a command's exit code (non-zero) with the
/// command's error lines as its message. Never returns.
[[noreturn]] void raise_for_exit_code(int exit_code, const std::string& error_text);

/// Raises puncture.SceneError with its attributes and the message the C++
/// SceneError would give ("file: /json/path: message"). Never returns.
[[noreturn]] void raise_scene_error(const std::string& file, const std::string& json_path, const std::string& message);

}  // namespace puncture::python
