// validate_binding.cpp: puncture.validate: `puncture validate` (the
// real-time model against the cached FEM reference, metrics per layer, the
// report) with the command's options, its files read back.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "command_call.hpp"
#include "command_outputs.hpp"
#include "python_progress.hpp"
#include "puncture/apps/commands.hpp"
#include "scene_handle.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

using OptionalPath = std::optional<std::filesystem::path>;

py::dict validate(const SceneHandle& scene, const OptionalPath& output_dir, const std::filesystem::path& cache_dir,
                  int refinement, int degree, bool write_vtk, const OptionalPath& cases, const std::string& model_note,
                  const OptionalPath& slab_rule, const OptionalPath& why_misses,
                  const std::vector<std::filesystem::path>& references, const OptionalPath& recording_format) {
  TemporaryDirectory tmp;
  apps::ValidateOptions o;
  o.scene = write_scene_file(scene.scene, tmp.path());
  o.output_dir = output_dir ? *output_dir : tmp.path() / "validation";
  o.cache_dir = cache_dir;
  o.refinement = refinement;
  o.degree = degree;
  o.write_vtk = write_vtk;
  o.cases = cases.value_or(std::filesystem::path());
  o.model_note = model_note;
  o.slab_rule = slab_rule.value_or(std::filesystem::path());
  o.why_misses = why_misses.value_or(std::filesystem::path());
  o.references = references;
  o.recording.format_file = recording_format.value_or(std::filesystem::path());
  o.quiet = true;
  PythonCallback interrupt{py::none()};
  o.fem_step = [&interrupt](double, double) { interrupt.check_signals(); };
  const CommandOutput printed =
      run_command([&](std::ostream& out, std::ostream& err) { return apps::validate_command(o, out, err); }, &interrupt);
  py::dict result = read_outputs(o.output_dir);
  result["output_dir"] = output_dir ? py::cast(*output_dir) : py::none();
  result["warnings"] = warning_lines(printed.err);
  return result;
}

}  // namespace

void bind_validate(py::module_& m) {
  m.def("validate", &validate, py::arg("scene"), py::kw_only(), py::arg("output_dir") = py::none(),
        py::arg("cache_dir") = std::filesystem::path(), py::arg("refinement") = -1, py::arg("degree") = -1,
        py::arg("write_vtk") = false, py::arg("cases") = py::none(), py::arg("model_note") = "",
        py::arg("slab_rule") = py::none(), py::arg("why_misses") = py::none(),
        py::arg("references") = std::vector<std::filesystem::path>{}, py::arg("recording_format") = py::none(),
        "`puncture validate` on the scene: the real-time model and the FEM reference (cached in cache_dir, default "
        "out/.fem_cache) on the same insertion. Returns the report's files as a dict by stem (validation_metrics, "
        "layer_metrics, force_depth_aligned, validation_summary, ...; with cases: heldout_summary and one folder per "
        "case, listed in 'files'), 'warnings', 'output_dir'. Writes the report to output_dir when given (staged: "
        "nothing half-written). Options as the command's (--cases, --model-note, --slab-rule, --why-misses; "
        "write_vtk = not --no-vtk). references: measured curves or raw recordings (--reference; recording_format: "
        "--recording-format): the scene's model judged against them instead of the FEM (recordings_validation, "
        "recording_curves, repeat_scatter). Raises puncture.InputError / RunError / OutputError with the command's message. "
        "The GIL is released; Ctrl-C stops an FEM reference being computed at its next load step.");
}

}  // namespace puncture::python
