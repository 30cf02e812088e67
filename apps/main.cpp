// puncture: command-line front end of the needle-puncture framework.
//   puncture run [SCENE] [-o DIR]      real-time SHF + MSM model
//   puncture fem [SCENE] [-o DIR]      deal.II FEM reference (mpirun-able)
#include <CLI/CLI.hpp>
#include <iostream>

#include "puncture/apps/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"puncture: virtual needle-puncture simulation (real-time SHF + MSM model, FEM reference)"};
  app.require_subcommand(1);

  puncture::apps::RunOptions run;
  std::string run_scene, run_out;
  auto* run_cmd = app.add_subcommand("run", "Run the real-time model along the scene's scripted insertion");
  run_cmd->add_option("scene", run_scene, "Scene file (JSON); default: scenes/default.json");
  run_cmd->add_option("-o,--output", run_out, "Output directory; default: out/<scene name>");
  run_cmd->add_flag("--no-frames", [&](std::int64_t) { run.write_frames = false; }, "Do not write VTK frames");
  run_cmd->add_flag("-q,--quiet", run.quiet, "No progress output");

  puncture::apps::FemOptions fem;
  std::string fem_scene, fem_out;
  auto* fem_cmd = app.add_subcommand("fem", "Run the deal.II FEM reference along the same insertion (MPI-aware)");
  fem_cmd->add_option("scene", fem_scene, "Scene file (JSON); default: scenes/default.json");
  fem_cmd->add_option("-o,--output", fem_out, "Output directory; default: out/<scene name>_fem");
  fem_cmd->add_option("--refinement", fem.refinement, "Global refinements (overrides the scene)")->check(CLI::Range(0, 4));
  fem_cmd->add_option("--degree", fem.degree, "Element degree 1 (Q1) or 2 (Q2) (overrides the scene)")->check(CLI::Range(1, 2));
  fem_cmd->add_flag("--no-vtu", [&](std::int64_t) { fem.write_vtu = false; }, "Do not write .vtu field output");

  CLI11_PARSE(app, argc, argv);

  if (*run_cmd) {
    run.scene = run_scene;
    run.output_dir = run_out;
    return puncture::apps::run_command(run, std::cout, std::cerr);
  }
  if (*fem_cmd) {
    fem.scene = fem_scene;
    fem.output_dir = fem_out;
    return puncture::apps::fem_command(fem, std::cout, std::cerr);
  }
  return 1;
}
