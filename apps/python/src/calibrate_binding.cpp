// calibrate_binding.cpp: puncture.calibrate: `puncture calibrate` (the force
// law tuned per layer against the cached FEM reference or a measured curve)
// with the command's options as keywords, a progress callback, Ctrl-C, and
// the tuned preset and report read back.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "command_call.hpp"
#include "command_outputs.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/scene_io.hpp"
#include "python_progress.hpp"
#include "reference_curve_file.hpp"
#include "scene_handle.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

/// Moves kw[key] into `field` if given.
template <class T>
void take(py::dict& kw, const char* key, T& field) {
  if (!kw.contains(key)) return;
  field = kw[key].cast<T>();
  PyDict_DelItemString(kw.ptr(), key);
}

/// The command's options from the keywords (TypeError for an unknown one).
apps::CalibrateOptions calibrate_options(py::dict kw) {
  apps::CalibrateOptions o;
  take(kw, "cache_dir", o.cache_dir);
  take(kw, "method", o.method);
  take(kw, "preset_name", o.preset_name);
  take(kw, "layers", o.layers);
  take(kw, "threads", o.threads);
  take(kw, "tune_unidentifiable", o.tune_unidentifiable);
  take(kw, "reference_depth_offset_mm", o.reference_depth_offset_mm);
  take(kw, "stage_turn_margin_mm", o.stage_turn_margin_mm);
  take(kw, "bound_factor", o.bound_factor);
  take(kw, "also_tune", o.also_tune);
  take(kw, "integrator", o.integrator);
  take(kw, "depth_weight", o.depth_weight);
  take(kw, "force_weight", o.force_weight);
  take(kw, "puncture_depths_mm", o.puncture_depths_mm);
  take(kw, "fem_speeds_mm_per_s", o.fem_speeds_mm_per_s);
  take(kw, "surface_fit", o.surface_fit);
  take(kw, "cutting_from_next_puncture", o.cutting_from_next_puncture);
  take(kw, "keep", o.keep);
  take(kw, "layer_thickness_mm", o.layer_thickness_mm);
  take(kw, "recording_format", o.recording.format_file);
  take(kw, "held_out", o.held_out);
  if (!kw.empty())
    throw py::type_error("calibrate() got an unexpected keyword argument '" +
                         py::str(py::list(kw.attr("keys")())[0]).cast<std::string>() + "'");
  return o;
}

/// One reference: a CSV path, or {column: array} written to `dir` as the i-th curve.
std::filesystem::path reference_path(const py::object& reference, const std::filesystem::path& dir, std::size_t i) {
  if (py::isinstance<py::str>(reference) || py::hasattr(reference, "__fspath__"))
    return reference.cast<std::filesystem::path>();
  const std::filesystem::path path = dir / ("reference_curve_" + std::to_string(i) + ".csv");
  write_reference_curve(reference, path);
  return path;
}

/// The references: None (the FEM's), one reference, or a list of them (repeats
/// and other speeds of the same tissue, calibrated against together).
std::vector<std::filesystem::path> reference_paths(const py::object& reference, const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> out;
  if (reference.is_none()) return out;
  if (py::isinstance<py::list>(reference) || py::isinstance<py::tuple>(reference)) {
    for (const py::handle& r : reference) out.push_back(reference_path(py::reinterpret_borrow<py::object>(r), dir, out.size()));
    return out;
  }
  out.push_back(reference_path(reference, dir, 0));
  return out;
}

py::dict calibrate(const SceneHandle& scene, const py::object& reference, const std::optional<std::filesystem::path>& output_dir,
                   const py::object& progress, const py::kwargs& kwargs) {
  TemporaryDirectory tmp;
  apps::CalibrateOptions o = calibrate_options(py::dict(kwargs));
  o.scene = write_scene_file(scene.scene, tmp.path());
  o.references = reference_paths(reference, tmp.path());
  o.output_dir = output_dir ? *output_dir : tmp.path() / "calibration";
  o.quiet = true;
  PythonCallback callback(progress);
  o.progress = [&callback](const validation::CalibrationProgress& p) { callback(p); };
  o.fem_step = [&callback](double, double) { callback.check_signals(); };
  const CommandOutput printed =
      run_command([&](std::ostream& out, std::ostream& err) { return apps::calibrate_command(o, out, err); }, &callback);
  py::dict result = read_outputs(o.output_dir);
  const std::string name = o.preset_name.empty() ? scene.scene.name + "_tuned" : o.preset_name;
  const std::filesystem::path preset = o.output_dir / (name + ".json");
  result["preset"] = SceneHandle{load_scene(preset), output_dir ? preset.string() : name + ".json"};
  result["output_dir"] = output_dir ? py::cast(*output_dir) : py::none();
  result["warnings"] = warning_lines(printed.err);
  return result;
}

}  // namespace

void bind_calibrate(py::module_& m) {
  py::class_<validation::CalibrationProgress>(m, "CalibrationProgress", "What calibrate()'s progress callback gets after every model run.")
      .def_readonly("evaluations", &validation::CalibrationProgress::evaluations, "model runs so far (all stages)")
      .def_readonly("best_objective", &validation::CalibrationProgress::best_objective, "of the current stage")
      .def_readonly("last_objective", &validation::CalibrationProgress::last_objective)
      .def_readonly("stage", &validation::CalibrationProgress::stage);
  m.def("calibrate", &calibrate, py::arg("scene"), py::kw_only(), py::arg("reference") = py::none(),
        py::arg("output_dir") = py::none(), py::arg("progress") = py::none(),
        "`puncture calibrate` on the scene: the force law tuned per layer against reference = None (the scene's FEM "
        "reference, cached in cache_dir), a CSV path (a curve or a raw recording), {column: array} (depth_mm and "
        "force_N; time_s, phase, <layer>_state, ... optional), or a list of these (repeats and other speeds of the "
        "same tissue, each at its own speed). The command's options as keywords: cache_dir, method, held_out (paths "
        "of recordings judged, not fitted), "
        "preset_name, layers, threads, tune_unidentifiable, reference_depth_offset_mm, stage_turn_margin_mm, "
        "bound_factor, also_tune, integrator, depth_weight, force_weight, puncture_depths_mm, fem_speeds_mm_per_s, "
        "surface_fit, cutting_from_next_puncture, keep, layer_thickness_mm, recording_format. progress(p) is called "
        "after every model run (a CalibrationProgress); raising in it, or Ctrl-C (also while an FEM reference is being "
        "computed), stops the calibration (nothing is written) and re-raises. Returns 'preset' (the tuned Scene), the files by stem (calibration_curves, "
        "calibration_summary, <preset>.provenance, ...), 'warnings', 'output_dir' (the files go there when given).");
}

}  // namespace puncture::python
