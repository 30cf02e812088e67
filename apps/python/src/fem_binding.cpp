// fem_binding.cpp: puncture.fem: the FEM reference of a scene from the cache
// `puncture validate` and `calibrate` use (validation/fem_cache), computed
// there when missing (in this process, deal.II; builds without the FEM raise
// puncture.RunError unless it is cached).
#include <sstream>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "command_call.hpp"
#include "command_outputs.hpp"
#include "errors.hpp"
#include "python_progress.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "scene_handle.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

validation::FemReferenceOptions fem_options(const std::filesystem::path& cache_dir, int refinement, int degree,
                                            bool write_vtu, bool verbose) {
  validation::FemReferenceOptions o;
  if (!cache_dir.empty()) o.cache_dir = cache_dir;
  o.refinement = refinement;
  o.degree = degree;
  o.write_vtu = write_vtu;
  o.verbose = verbose;
  return o;
}

py::dict fem(const SceneHandle& scene, const std::filesystem::path& cache_dir, int refinement, int degree, bool write_vtu,
             const std::optional<std::filesystem::path>& output_dir, bool verbose, const py::object& progress) {
  validation::FemReferenceOptions options = fem_options(cache_dir, refinement, degree, write_vtu, verbose);
  PythonCallback callback(progress);
  options.on_step = [&callback](double, double fraction_done) { callback(fraction_done); };
  validation::FemReference ref;
  std::ostringstream log;
  run_command([&](std::ostream&, std::ostream& err) {
    try {
      ref = validation::obtain_fem_reference(scene.scene, options, log);
      return 0;
    } catch (const std::exception& e) {
      err << "error: " << scene.source << ": " << e.what() << '\n';
      return 1;
    }
  }, &callback);
  if (output_dir) run_command([&](std::ostream&, std::ostream& err) {
      try {
        copy_outputs(ref.dir, *output_dir);
        return 0;
      } catch (const std::exception& e) {
        err << "error: " << e.what() << '\n';
        return 3;
      }
    });
  py::dict result = read_outputs(ref.dir);
  result["dir"] = ref.dir;
  result["hash"] = ref.hash;
  result["from_cache"] = ref.from_cache;
  result["output_dir"] = output_dir ? py::cast(*output_dir) : py::none();
  result["log"] = log.str();
  return result;
}

}  // namespace

void bind_fem(py::module_& m) {
  m.def("fem", &fem, py::arg("scene"), py::kw_only(), py::arg("cache_dir") = std::filesystem::path(),
        py::arg("refinement") = -1, py::arg("degree") = -1, py::arg("write_vtu") = false,
        py::arg("output_dir") = py::none(), py::arg("verbose") = false, py::arg("progress") = py::none(),
        "The deal.II FEM reference of the scene's insertion, from the cache of `puncture validate` and `calibrate` "
        "(cache_dir, default out/.fem_cache; key: everything the FEM reads) or computed into it. Returns a dict: "
        "'fem_force_depth' ({column: array}), 'fem_summary' (dict), the other files by stem, 'files', 'dir', "
        "'hash', 'from_cache', 'log'. output_dir: a copy of the files there. refinement / degree -1: the scene's. "
        "progress(fraction) is called after every load step of an FEM being computed (fraction of the trajectory "
        "done, by time). The GIL is released while the FEM runs; Ctrl-C, or an exception raised in progress, stops "
        "it at its next load step (nothing is cached) and re-raises.");
  m.def(
      "fem_cache_key",
      [](const SceneHandle& scene, int refinement, int degree) {
        const std::string key = validation::fem_reference_key_text(scene.scene, fem_options({}, refinement, degree, false, false));
        return py::dict(py::arg("key") = key, py::arg("hash") = validation::fem_reference_key_hash(key));
      },
      py::arg("scene"), py::kw_only(), py::arg("refinement") = -1, py::arg("degree") = -1,
      "The key of the scene's FEM reference in the cache: {'key': the text of its fem_reference_key.json, "
      "'hash': the name of its folder under cache_dir}.");
}

}  // namespace puncture::python
