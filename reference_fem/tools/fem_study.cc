// fem_study: command-line driver of the FEM reference for studies and
// benchmarks (the project's `puncture fem` command calls the same
// run_needle_insertion). Prints one Markdown table row per run on rank 0.
//
//   fem_study run SCENE OUT_DIR [REFINEMENT] [DEGREE]
//       full insertion of the scene, files in OUT_DIR; the environment may
//       set the linear solver (PUNCTURE_FEM_LINEAR_SOLVER=auto|direct|iterative)
//       and the 3D slab's mesh (PUNCTURE_FEM_SECTORS: cells around the
//       circumference, a multiple of 4; PUNCTURE_FEM_RADIAL_GRADING: >= 1)
//   fem_study indent SCENE DEPTH_MM SECTORS REFINEMENT DEGREE [FORMULATION]
//       indentation without puncture to DEPTH_MM; row:
//       | sectors | refinement | Q | formulation | dofs | force at depth (N) | wall (s) |
//   fem_study bench SCENE DEPTH_MM SECTORS REFINEMENT DEGREE
//       row: | ranks | dofs | load steps | Newton its | linear its per Newton it | s per Newton it |
//            s per load step | wall (s) |
#include <deal.II/base/mpi.h>

#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <string>

#include <puncture/fem/needle_insertion.hpp>
#include <puncture/scene_io.hpp>

using namespace puncture;

int main(int argc, char** argv) {
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool root = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  try {
    if (argc < 3) throw std::invalid_argument("usage: fem_study run|indent|bench SCENE ...");
    const std::string mode = argv[1];
    Scene scene = load_scene(argv[2]);
    fem::FemRunOptions o;
    if (mode == "run") {
      if (argc < 4) throw std::invalid_argument("usage: fem_study run SCENE OUT_DIR [REFINEMENT] [DEGREE]");
      o.output_dir = argv[3];
      if (argc > 4) o.refinement_override = std::atoi(argv[4]);
      if (argc > 5) o.degree_override = std::atoi(argv[5]);
      if (const char* ls = std::getenv("PUNCTURE_FEM_LINEAR_SOLVER")) o.linear_solver = ls;
      if (const char* sec = std::getenv("PUNCTURE_FEM_SECTORS")) o.mesh.sectors = std::atoi(sec);
      if (const char* g = std::getenv("PUNCTURE_FEM_RADIAL_GRADING")) o.mesh.radial_grading = std::atof(g);
      const auto s = fem::run_needle_insertion(scene, o, MPI_COMM_WORLD);
      if (root)
        std::cout << "dofs " << s.n_dofs << ", wall " << s.wall_time_s << " s, punctures " << s.punctures.size()
                  << ", peak force " << s.peak_force_N << " N" << std::endl;
      return 0;
    }
    if (argc < 7) throw std::invalid_argument("usage: fem_study indent|bench SCENE DEPTH_MM SECTORS REFINEMENT DEGREE");
    const double depth = std::atof(argv[3]) * 1e-3;
    o.mesh.sectors = std::atoi(argv[4]);
    o.refinement_override = std::atoi(argv[5]);
    o.degree_override = std::atoi(argv[6]);
    if (argc > 7) o.formulation = argv[7];
    if (const char* ls = std::getenv("PUNCTURE_FEM_LINEAR_SOLVER")) o.linear_solver = ls;
    o.write_files = false;
    o.verbose = false;
    for (auto& l : scene.layers) {  // indentation only: nothing breaks
      l.puncture.kind = PunctureCriterion::Kind::CriticalForce;
      l.puncture.critical_force_N = 1e30;
    }
    scene.insertion.start_height_m = 0.0;
    o.stop_depth_m = depth;
    const auto s = fem::run_needle_insertion(scene, o, MPI_COMM_WORLD);
    if (!root) return 0;
    std::cout << std::setprecision(6);
    if (mode == "indent")
      std::cout << "| " << o.mesh.sectors << " | " << o.refinement_override << " | Q" << o.degree_override << " | "
                << o.formulation << " | " << s.n_dofs << " | " << s.force_N.back() << " | " << std::setprecision(3)
                << s.wall_time_s << " |" << std::endl;
    else
      std::cout << "| " << s.n_ranks << " | " << s.n_dofs << " | " << s.load_steps << " | " << s.newton_iterations
                << " | " << s.linear_iterations / std::max(1, s.newton_iterations) << " | " << std::setprecision(3) << s.solve_time_s / std::max(1, s.newton_iterations) << " | "
                << s.solve_time_s / std::max(1, s.load_steps) << " | " << s.wall_time_s << " |" << std::endl;
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "fem_study: " << e.what() << std::endl;
    return 1;
  }
}
