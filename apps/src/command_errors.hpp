// command_errors.hpp: how every subcommand turns an exception into a message
// and an exit code (internal to puncture_app_lib).
#pragma once

#include <exception>
#include <ostream>
#include <string>

#include "puncture/scene_io.hpp"

namespace puncture::apps {

/// Runs `body` (returns the exit code). A SceneError (its message names the
/// file and the JSON path) gives exit code 2; any other exception gives 1,
/// its message prefixed by `context` (e.g. the scene file) when not empty.
template <class Body>
int report_errors(std::ostream& err, const std::string& context, Body&& body) {
  try {
    return body();
  } catch (const SceneError& e) {
    err << "error: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    err << "error: " << (context.empty() ? "" : context + ": ") << e.what() << '\n';
    return 1;
  }
}

}  // namespace puncture::apps
