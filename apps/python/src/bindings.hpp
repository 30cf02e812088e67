// bindings.hpp: the parts of the Python module `puncture`, one function per
// file (module.cpp calls them in this order: the exceptions first, as the
// others raise them).
#pragma once

#include <pybind11/pybind11.h>

namespace puncture::python {

void bind_errors(pybind11::module_& m);      // errors.cpp: SceneError, InputError, RunError, OutputError
void bind_scene(pybind11::module_& m);       // scene_binding.cpp: Scene
void bind_tick(pybind11::module_& m);        // tick_binding.cpp: Tick, LayerTick, PunctureEvent
void bind_run_result(pybind11::module_& m);  // run_result.cpp: RunResult
void bind_simulator(pybind11::module_& m);   // simulator_binding.cpp: Simulator
void bind_commands(pybind11::module_& m);    // commands_binding.cpp: the four below, MPI finalised at exit
void bind_fem(pybind11::module_& m);         // fem_binding.cpp: fem, fem_cache_key
void bind_validate(pybind11::module_& m);    // validate_binding.cpp: validate
void bind_calibrate(pybind11::module_& m);   // calibrate_binding.cpp: calibrate
void bind_compare(pybind11::module_& m);     // compare_binding.cpp: compare (builds with VTK)

}  // namespace puncture::python
