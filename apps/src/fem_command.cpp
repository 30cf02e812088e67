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

#include <sstream>

#include "puncture/fem/needle_insertion.hpp"
#include "puncture/meshing/inclined_path_mesh.hpp"
#endif

namespace puncture::apps {

#ifdef PUNCTURE_HAVE_FEM
namespace {

/// `puncture fem` at an angle: the 3D reference (a blunt tip) takes one, on a
/// mesh whose needle column follows the path (meshing/inclined_path_mesh.hpp),
/// while that mesh stays valid; the axisymmetric reference does not.
void require_fem_takes_the_angle(const Scene& scene, const std::string& file) {
  if (scene.insertion.angle_deg == 0.0) return;
  if (fem::resolved_geometry(scene) != "3d")
    require_axial_for_fem(scene, file, "the axisymmetric FEM reference (a '" + scene.needle.tip +
                                           "' tip; the 3d reference, a blunt tip, takes an angle)");
  const double bound = meshing::inclined_path_jacobian_bound(meshing::inclined_path_of(scene));
  if (!(bound >= meshing::kMinInclinedPathJacobian)) {
    std::ostringstream msg;
    msg << scene.insertion.angle_deg << " deg to " << scene.insertion.target_depth_m * 1e3
        << " mm: the 3D reference's mesh cannot follow the needle's path in a sample of diameter "
        << scene.sample.diameter_m * 1e3 << " mm (its Jacobian bound " << bound << " < "
        << meshing::kMinInclinedPathJacobian << "; reduce the angle or the target depth, or widen /sample/diameter_mm)";
    throw SceneError(file, "/insertion/angle_deg", msg.str());
  }
}

}  // namespace
#endif

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
    require_fem_takes_the_angle(scene, scene_path.string());
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
