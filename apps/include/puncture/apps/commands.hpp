// commands.hpp: the subcommands of the `puncture` program as functions.
// Each returns the process exit code (0 on success) and prints progress and
// a short report to `out`, errors to `err`. Outputs are written through an
// io::OutputSession: on any error nothing half-written is left behind.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>

namespace puncture::apps {

/// The scene `puncture run` uses without arguments: scenes/default.json in the
/// working directory if present, else the one in the source tree.
std::filesystem::path default_scene_path();

struct RunOptions {
  std::filesystem::path scene;        ///< empty: default_scene_path()
  std::filesystem::path output_dir;   ///< empty: out/<scene name>
  bool write_frames = true;           ///< VTK surface frames (also needs Effects::surface_output)
  bool quiet = false;                 ///< no progress lines
};

/// `puncture run`: real-time model along the scene's scripted insertion.
/// Writes realtime_curve.csv, summary.json, sh_fit_error.csv and, with the
/// surface_output effect, frames/*.vtp + realtime.pvd.
int run_command(const RunOptions& options, std::ostream& out, std::ostream& err);

struct FemOptions {
  std::filesystem::path scene;
  std::filesystem::path output_dir;   ///< empty: out/<scene name>_fem
  int refinement = -1;                ///< -1: from the scene
  int degree = -1;                    ///< -1: from the scene
  bool write_vtu = true;
};

/// `puncture fem`: the deal.II reference along the same insertion (MPI-aware).
int fem_command(const FemOptions& options, std::ostream& out, std::ostream& err);

}  // namespace puncture::apps
