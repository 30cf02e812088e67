// fem_reference.cpp: the FEM reference of a scene, cached on disk.
//
// Cache layout: <cache_dir>/<hash>/ holds the files of fem::run_needle_insertion
// plus fem_reference_key.json (the exact text that was hashed, for a human who
// wonders why two runs did or did not share a reference). A new reference is
// computed into <cache_dir>/.tmp-<hash>/ and renamed into place only when the
// FEM succeeded, so the cache never holds a half-written reference. An entry
// is reused only when its stored key text equals the current one, so an entry
// of an older key format (or a hash collision) is recomputed, never reused.
//
// The key is derived from everything the FEM reads: fem_reference_key.hpp.
#include "puncture/validation/fem_reference.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

#include "puncture/io/interrupt_cleanup.hpp"
#include "puncture/io/provenance.hpp"

#ifdef PUNCTURE_HAVE_FEM
#include <deal.II/base/mpi.h>

#include "puncture/fem/cpu_affinity.hpp"
#include "puncture/fem/needle_insertion.hpp"
#endif

#ifndef PUNCTURE_FEM_SOURCE_DIGEST
#define PUNCTURE_FEM_SOURCE_DIGEST "none"
#endif

namespace puncture::validation {

namespace {

FemKeyOptions key_options(const FemReferenceOptions& options) {
  FemKeyOptions k;
  k.refinement = options.refinement;
  k.degree = options.degree;
#ifdef PUNCTURE_HAVE_FEM
  char buffer[40];
  const auto exact = [&buffer](double x) {
    std::snprintf(buffer, sizeof buffer, "%.17g", x);
    return std::string(buffer);
  };
  k.mesh_options = {{"elements_through_skin", std::to_string(options.mesh.elements_through_skin)},
                    {"radial_grading", exact(options.mesh.radial_grading)},
                    {"sectors", std::to_string(options.mesh.sectors)},
                    {"thickness_grading", exact(options.mesh.thickness_grading)}};
#endif
  return k;
}

/// A complete reference of this key: the stored key text is `key_text`, the
/// summary says it finished and the curve exists.
bool reference_complete(const std::filesystem::path& dir, bool need_vtu, const std::string& key_text) {
  if (!cached_key_matches(dir, key_text)) return false;
  const auto summary_path = dir / "fem_summary.json";
  if (!std::filesystem::is_regular_file(summary_path) || !std::filesystem::is_regular_file(dir / "fem_force_depth.csv"))
    return false;
  if (need_vtu && !std::filesystem::is_regular_file(dir / "fem_fields.pvd")) return false;
  std::ifstream in(summary_path);
  nlohmann::json summary = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (summary.is_discarded()) return false;
  return !(summary.contains("status") && summary["status"] == "failed");
}

}  // namespace

std::string fem_source_digest() { return PUNCTURE_FEM_SOURCE_DIGEST; }

std::string fem_reference_key_text(const Scene& scene, const FemReferenceOptions& options) {
  return fem_reference_key_text(scene, key_options(options), PUNCTURE_FEM_SOURCE_DIGEST);
}

std::string fem_reference_hash(const Scene& scene, const FemReferenceOptions& options) {
  return fem_reference_key_hash(fem_reference_key_text(scene, options));
}

bool cached_key_matches(const std::filesystem::path& dir, const std::string& key_text) {
  std::ifstream in(dir / "fem_reference_key.json", std::ios::binary);
  if (!in) return false;
  std::ostringstream stored;
  stored << in.rdbuf();
  return stored.str() == key_text;
}

#ifdef PUNCTURE_HAVE_FEM
namespace {
std::unique_ptr<dealii::Utilities::MPI::MPI_InitFinalize>& mpi_session() {
  static std::unique_ptr<dealii::Utilities::MPI::MPI_InitFinalize> session;
  return session;
}

/// The ranks other than 0 have only helped with the FEM references; they
/// wait here, asleep (a test every 20 ms), until rank 0 has done the rest of
/// the command and releases them. Left to MPI_Finalize, OpenMPI's wait polls
/// (measured: about a fifth of a core for the whole of rank 0's run, on the
/// core rank 0's second thread would use).
void release_or_wait_for_root() {
  int size = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size < 2) return;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  constexpr int kDoneTag = 7301;
  if (rank == 0) {
    for (int other = 1; other < size; ++other) MPI_Send(nullptr, 0, MPI_BYTE, other, kDoneTag, MPI_COMM_WORLD);
    return;
  }
  MPI_Request request;
  MPI_Irecv(nullptr, 0, MPI_BYTE, 0, kDoneTag, MPI_COMM_WORLD, &request);
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}
}  // namespace
#endif

void ensure_mpi() {
#ifdef PUNCTURE_HAVE_FEM
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (initialised) return;
  // OpenMPI refuses to start as root unless told it may (CI runs as root);
  // only set when the user did not decide.
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
  static int argc = 1;
  static char program[] = "puncture";
  static char* argv_storage[] = {program, nullptr};
  static char** argv = argv_storage;
  mpi_session() = std::make_unique<dealii::Utilities::MPI::MPI_InitFinalize>(argc, argv, 1);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  // Rank 0 does the command's work after the FEM references (the optimisers,
  // the held-out runs) while the other ranks sleep.
  if (rank == 0) puncture::fem::widen_cpu_affinity();
#endif
}

bool is_mpi_root() {
#ifdef PUNCTURE_HAVE_FEM
  int finalised = 0;
  MPI_Finalized(&finalised);
  if (finalised) return true;
  ensure_mpi();  // a cached reference does not start MPI, but mpirun may have started us
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) return true;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank == 0;
#else
  return true;
#endif
}

void finalize_mpi() {
#ifdef PUNCTURE_HAVE_FEM
  if (mpi_session()) release_or_wait_for_root();
  mpi_session().reset();
#endif
}

FemReference obtain_fem_reference(const Scene& scene, const FemReferenceOptions& options, std::ostream& out) {
  FemReference ref;
  const std::string key_text = fem_reference_key_text(scene, options);
  ref.hash = fem_reference_key_hash(key_text);
  ref.dir = options.cache_dir / ref.hash;
  if (reference_complete(ref.dir, options.write_vtu, key_text)) {
    ref.from_cache = true;
    if (options.verbose) out << "[fem] reference from cache " << ref.dir.string() << "\n";
    return ref;
  }
#ifdef PUNCTURE_HAVE_FEM
  ensure_mpi();
  const bool root = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  const std::filesystem::path staging = options.cache_dir / (".tmp-" + ref.hash);
  if (root) {
    std::filesystem::create_directories(options.cache_dir);
    std::filesystem::remove_all(staging);  // left by an earlier run of the same key that died
    io::register_cleanup(staging, io::CleanupKind::Tree);  // an interrupted run leaves nothing
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (options.verbose && root)
    out << "[fem] no cached reference " << ref.hash << ": running the FEM (" << scene.name << ")\n" << std::flush;

  fem::FemRunOptions fem_options;
  fem_options.output_dir = staging.string();
  fem_options.refinement_override = options.refinement;
  fem_options.degree_override = options.degree;
  fem_options.write_vtu = options.write_vtu;
  fem_options.verbose = options.verbose;
  fem_options.mesh = options.mesh;
  fem_options.on_step = options.on_step;
  try {
    fem::run_needle_insertion(scene, fem_options, MPI_COMM_WORLD);
    if (root) {
      std::ofstream key(staging / "fem_reference_key.json");
      key << key_text;
      if (!key) throw std::runtime_error("cannot write " + (staging / "fem_reference_key.json").string());
    }
  } catch (...) {
    if (root) {
      std::error_code ignored;
      std::filesystem::remove_all(staging, ignored);
      io::unregister_cleanup(staging);
    }
    throw;
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (root) {
    // Replace an incomplete or vtu-less reference of the same key.
    std::filesystem::remove_all(ref.dir);
    std::filesystem::rename(staging, ref.dir);
    io::unregister_cleanup(staging);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (options.verbose && root) out << "[fem] reference cached in " << ref.dir.string() << "\n";
  return ref;
#else
  (void)out;
  throw std::runtime_error("no cached FEM reference " + ref.dir.string() +
                           " and this build has no FEM (configure with -DPUNCTURE_WITH_FEM=ON)");
#endif
}

}  // namespace puncture::validation
