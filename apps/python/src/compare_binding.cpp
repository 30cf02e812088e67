// compare_binding.cpp: puncture.compare: `puncture compare` (every
// comparison model and the real-time model against the cached FEM
// reference, graded) with the command's options, its files read back.
// Built with VTK only, as the command.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "command_call.hpp"
#include "command_outputs.hpp"
#include "errors.hpp"
#include "puncture/apps/commands.hpp"
#include "python_progress.hpp"
#include "scene_handle.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

using OptionalPath = std::optional<std::filesystem::path>;

#ifdef PUNCTURE_HAVE_COMPARE
py::dict compare(const SceneHandle& scene, const std::vector<std::string>& models, const OptionalPath& output_dir,
                 const std::filesystem::path& cache_dir, const OptionalPath& weights, const std::vector<std::string>& identify,
                 int identify_evaluations, bool scene_parameters, bool critical_forces_only, const OptionalPath& cases,
                 int frames, bool write_vtk) {
  TemporaryDirectory tmp;
  apps::CompareOptions o;
  o.scene = write_scene_file(scene.scene, tmp.path());
  o.output_dir = output_dir ? *output_dir : tmp.path() / "comparison";
  o.cache_dir = cache_dir;
  o.weights = weights.value_or(std::filesystem::path());
  o.models = models;
  o.identify = identify;
  o.identify_evaluations = identify_evaluations;
  o.scene_parameters = scene_parameters;
  o.critical_forces_only = critical_forces_only;
  o.cases = cases.value_or(std::filesystem::path());
  o.frames = frames;
  o.write_vtk = write_vtk;
  o.quiet = true;
  PythonCallback interrupt{py::none()};
  o.fem_step = [&interrupt](double, double) { interrupt.check_signals(); };
  o.model_step = [&interrupt] { interrupt.check_signals(); };
  const CommandOutput printed =
      run_command([&](std::ostream& out, std::ostream& err) { return apps::compare_command(o, out, err); }, &interrupt);
  py::dict result = read_outputs(o.output_dir);
  result["output_dir"] = output_dir ? py::cast(*output_dir) : py::none();
  result["warnings"] = warning_lines(printed.err);
  return result;
}
#else
py::dict compare(const SceneHandle&, const std::vector<std::string>&, const OptionalPath&, const std::filesystem::path&,
                 const OptionalPath&, const std::vector<std::string>&, int, bool, bool, const OptionalPath&, int, bool) {
  raise_for_exit_code(1, "error: this build has no `puncture compare` (configure with -DPUNCTURE_WITH_VTK=ON)");
}
#endif

}  // namespace

void bind_compare(py::module_& m) {
  m.def("compare", &compare, py::arg("scene"), py::kw_only(), py::arg("models") = std::vector<std::string>{},
        py::arg("output_dir") = py::none(), py::arg("cache_dir") = std::filesystem::path(), py::arg("weights") = py::none(),
        py::arg("identify") = std::vector<std::string>{}, py::arg("identify_evaluations") = 40,
        py::arg("scene_parameters") = false, py::arg("critical_forces_only") = false, py::arg("cases") = py::none(),
        py::arg("frames") = 0, py::arg("write_vtk") = false,
        "`puncture compare` on the scene: the comparison models of both papers and the real-time model against the "
        "FEM reference (cached), graded. Returns the files by stem (comparison and ranking as arrays, "
        "comparison_summary, 'comparison.md' as text: a stem two files share keeps the file name), 'files', "
        "'warnings', 'output_dir'; options as the command's (models empty: all; frames 0 and write_vtk False: no "
        "ParaView series). Runs for minutes with every model; the GIL is released, and Ctrl-C stops it within 5 % "
        "of a model run (or at the FEM's next load step), writing nothing.");
}

}  // namespace puncture::python
