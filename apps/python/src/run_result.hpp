// run_result.hpp: puncture.RunResult, a whole scripted insertion as NumPy
// arrays by name. The arrays are allocated once and filled from the C++ run
// (ScriptedRunResult) in C++ loops: no Python object per tick.
#pragma once

#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene.hpp"

namespace puncture::python {

struct RunResult {
  pybind11::dict arrays;  ///< name -> numpy array (see run_result.cpp for the list)
  pybind11::list events;  ///< PunctureEvent, in order
  std::vector<std::string> layer_names;
  double time_step_s = 0.0;
};

/// Needs the GIL. `scene` gives the phases and the layer names.
RunResult make_run_result(const Scene& scene, const ScriptedRunResult& run);

/// The names of the codes in RunResult's `phase` and `layer_state` arrays.
const std::vector<std::string>& phase_names();
const std::vector<std::string>& state_names();

}  // namespace puncture::python
