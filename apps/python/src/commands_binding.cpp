// commands_binding.cpp: the commands of the `puncture` program as Python
// functions (fem, validate, calibrate, compare), and MPI, which the FEM
// starts in this process, finalised when Python exits.
#include "bindings.hpp"
#include "puncture/validation/fem_reference.hpp"

namespace py = pybind11;

namespace puncture::python {

void bind_commands(py::module_& m) {
  bind_fem(m);
  bind_validate(m);
  bind_calibrate(m);
  bind_compare(m);
  // fem_reference.hpp: finalise MPI before exit, not from a static destructor.
  py::module_::import("atexit").attr("register")(py::cpp_function([]() { validation::finalize_mpi(); }));
}

}  // namespace puncture::python
