// `puncture fem`: the deal.II reference along the scene's insertion. Runs
// unchanged under `mpirun -np N puncture fem ...`; rank 0 prints.
#include <iostream>

#include "command_errors.hpp"
#include "measured_reference.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/scene_io.hpp"

#ifdef PUNCTURE_HAVE_FEM
#include <deal.II/base/mpi.h>

#include "puncture/fem/needle_insertion.hpp"
#endif

namespace puncture::apps {

int fem_command(const FemOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
#ifdef PUNCTURE_HAVE_FEM
  validation::ensure_mpi();
  const bool root = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  NullStream silent;
  return report_errors(root ? err : silent, scene_path.string(), [&]() -> int {
    const Scene scene = load_scene(scene_path);
    require_axial_for_fem(scene, scene_path.string(), "the FEM reference");
    fem::FemRunOptions fem_options;
    fem_options.output_dir =
        (options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_fem") : options.output_dir).string();
    fem_options.refinement_override = options.refinement;
    fem_options.degree_override = options.degree;
    fem_options.write_vtu = options.write_vtu;
    fem_options.stop_depth_m = options.stop_depth_mm > 0.0 ? options.stop_depth_mm * 1e-3 : -1.0;
    fem_options.verbose = !options.quiet;
    const fem::FemRunSummary summary = fem::run_needle_insertion(scene, fem_options, MPI_COMM_WORLD);
    if (root) {
      out << "\nFEM puncture events (" << summary.punctures.size() << "):\n";
      for (const auto& e : summary.punctures)
        out << "  " << e.layer_name << "  depth = " << e.depth_m * 1e3 << " mm   force = " << e.force_N << " N\n";
      out << "FEM: " << summary.n_dofs << " DoFs, " << summary.n_ranks << " rank(s), " << summary.load_steps
          << " load steps, " << summary.newton_iterations << " Newton iterations, " << summary.wall_time_s
          << " s\nOutputs in " << fem_options.output_dir << "/ (fem_force_depth.csv, fem_summary.json, fem_fields.pvd)\n";
    }
    return 0;
  });
#else
  (void)options;
  (void)out;
  err << "error: this build has no FEM reference (configure with -DPUNCTURE_WITH_FEM=ON)\n";
  return kExitFailure;
#endif
}

}  // namespace puncture::apps
