// fem_reference.hpp: the FEM reference of a scene, computed once and cached
// on disk, keyed by everything the FEM reads (fem_reference_key.hpp: the
// scene's canonical JSON minus its real-time-only fields, the refinement /
// degree overrides, the mesh options, the program version and a digest of the
// FEM sources).
//
// In:  a Scene, options (cache directory, overrides), a stream for progress.
// Out: the directory holding fem_force_depth.csv, fem_surface_profile.csv,
//      fem_recovery_profile.csv, fem_summary.json, fem_fields.pvd (+ .vtu),
//      the hash, and whether it came from the cache.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <functional>
#include <string>

#include "puncture/scene.hpp"
#include "puncture/validation/fem_reference_key.hpp"

#ifdef PUNCTURE_HAVE_FEM
#include <puncture/meshing/layered_cylinder_mesh.hpp>
#endif

namespace puncture::validation {

struct FemReferenceOptions {
  std::filesystem::path cache_dir = "out/.fem_cache";
  int refinement = -1;  ///< -1: from the scene
  int degree = -1;      ///< -1: from the scene
  bool write_vtu = true;
  bool verbose = true;
  /// When the reference is computed: called after every converged load step
  /// with the tip depth (m) and the share of the trajectory done (0..1); may
  /// throw to stop the FEM (nothing is cached). FemRunOptions::on_step.
  std::function<void(double depth_m, double fraction_done)> on_step;
#ifdef PUNCTURE_HAVE_FEM
  meshing::SlabMeshOptions mesh;  ///< hex mesh resolution (tests and studies use coarser ones)
#endif
};

struct FemReference {
  std::filesystem::path dir;
  std::string hash;
  bool from_cache = false;
};

/// This build's FEM source digest: 16 hex digits of the SHA-256 over the
/// sources of reference_fem/ and meshing/ (validation/fem_cache/CMakeLists.txt);
/// part of every cache key, and shown by `puncture --version`.
std::string fem_source_digest();

/// The key text of `scene` with `options` (fem_reference_key_text with this
/// build's FEM source digest and the options' overrides and mesh).
std::string fem_reference_key_text(const Scene& scene, const FemReferenceOptions& options);

/// Hash (hex) of everything that affects the FEM result of `scene` with `options`.
std::string fem_reference_hash(const Scene& scene, const FemReferenceOptions& options);

/// True when `dir` holds fem_reference_key.json with exactly `key_text`
/// (an entry of another key format, or a colliding hash, does not match).
bool cached_key_matches(const std::filesystem::path& dir, const std::string& key_text);

/// Returns the cached reference or runs the FEM (in this process, MPI
/// initialised once per process by ensure_mpi()) and caches it.
FemReference obtain_fem_reference(const Scene& scene, const FemReferenceOptions& options, std::ostream& out);

/// Initialises MPI (and deal.II's MPI-dependent libraries) once per process;
/// later calls do nothing.
void ensure_mpi();

/// True on MPI rank 0 and when MPI is not running. Under `mpirun -np N
/// puncture validate|calibrate|sweep` every rank takes part in the FEM
/// reference; only rank 0 goes on to the real-time model and the reports.
bool is_mpi_root();

/// Finalises what ensure_mpi() initialised (nothing if it was not called).
/// Call it before main() returns: finalising from a static destructor at exit
/// races with the destruction of other libraries' statics. Under mpirun every
/// rank calls it: the ranks other than 0 wait in it asleep until rank 0 gets
/// there (they helped with the FEM only), rank 0 releases them.
void finalize_mpi();

}  // namespace puncture::validation
