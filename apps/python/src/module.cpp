// module.cpp: the Python module `puncture` (apps/python/README.md).
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "puncture/io/provenance.hpp"

PYBIND11_MODULE(puncture, m) {
  m.doc() =
      "puncture: the real-time needle-puncture model (SH layer surfaces, force meshes, the force law), "
      "its scenes, and the FEM reference, calibration and validation of the `puncture` program.\n"
      "Lengths in mm where a name ends in _mm, everything else SI.";
  puncture::python::bind_errors(m);
  puncture::python::bind_scene(m);
  puncture::python::bind_tick(m);
  puncture::python::bind_run_result(m);
  puncture::python::bind_simulator(m);
  puncture::python::bind_commands(m);
  m.attr("__version__") = puncture::io::program_version();
  m.attr("git_revision") = puncture::io::git_revision();
#ifdef PUNCTURE_HAVE_FEM
  m.attr("HAVE_FEM") = true;
#else
  m.attr("HAVE_FEM") = false;
#endif
}
