// fem_reference.cpp: the FEM reference of a scene, cached on disk.
//
// Cache layout: <cache_dir>/<hash>/ holds the files of fem::run_needle_insertion
// plus fem_reference_key.json (the exact text that was hashed, for a human who
// wonders why two runs did or did not share a reference). A new reference is
// computed into <cache_dir>/.tmp-<hash>/ and renamed into place only when the
// FEM succeeded, so the cache never holds a half-written reference.
//
// The key holds every input that changes the FEM result: sample diameter,
// needle radius and tip, per layer thickness, density, continuum material and
// puncture criterion, the insertion start height, speed, target depth and
// angle (the FEM stops at the target depth: dwell and withdrawal do not enter),
// the FEM settings (with the refinement/degree overrides applied), the mesh
// options, and the program version plus a digest of the FEM and mesh sources
// (PUNCTURE_FEM_SOURCE_DIGEST, computed by apps/CMakeLists.txt). Realtime-only
// fields (K, d, w, L, surface stiffness, thresholds, resumption rate, SH
// degree, haptic rate, integrator, effects, names) are not in it.
#include "puncture/apps/fem_reference.hpp"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "puncture/io/content_hash.hpp"
#include "puncture/io/interrupt_cleanup.hpp"
#include "puncture/io/provenance.hpp"

#ifdef PUNCTURE_HAVE_FEM
#include <deal.II/base/mpi.h>

#include "puncture/fem/needle_insertion.hpp"
#endif

#ifndef PUNCTURE_FEM_SOURCE_DIGEST
#define PUNCTURE_FEM_SOURCE_DIGEST "none"
#endif

namespace puncture::apps {

namespace {

/// Shortest text that reads back to the same double (so equal inputs give equal keys).
std::string exact(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

const char* criterion_name(PunctureCriterion::Kind kind) {
  return kind == PunctureCriterion::Kind::CriticalForce ? "critical_force" : "critical_stretch";
}

/// The text that is hashed (JSON, numbers in SI units printed exactly).
std::string fem_reference_key_text(const Scene& scene, const FemReferenceOptions& options) {
  nlohmann::ordered_json key;
  key["program_version"] = io::program_version();
  key["fem_source_digest"] = PUNCTURE_FEM_SOURCE_DIGEST;
  key["sample_diameter_m"] = exact(scene.sample.diameter_m);
  key["needle"] = {{"radius_m", exact(scene.needle.radius_m)}, {"tip", scene.needle.tip}};
  nlohmann::ordered_json layers = nlohmann::ordered_json::array();
  for (const Layer& l : scene.layers) {
    nlohmann::ordered_json j;
    j["thickness_m"] = exact(l.thickness_m);
    j["density_kg_per_m3"] = exact(l.density_kg_per_m3);
    j["material"] = {{"model", l.material.model},
                     {"youngs_modulus_Pa", exact(l.material.youngs_modulus_Pa)},
                     {"poisson_ratio", exact(l.material.poisson_ratio)},
                     {"mooney_rivlin_c01_fraction", exact(l.material.mooney_rivlin_c01_fraction)}};
    j["puncture"] = {{"criterion", criterion_name(l.puncture.kind)}};
    if (l.puncture.kind == PunctureCriterion::Kind::CriticalForce)
      j["puncture"]["critical_force_N"] = exact(l.puncture.critical_force_N);
    else
      j["puncture"]["critical_stretch"] = exact(l.puncture.critical_stretch);
    layers.push_back(j);
  }
  key["layers"] = layers;
  const Insertion& in = scene.insertion;
  key["insertion"] = {{"start_height_m", exact(in.start_height_m)},
                      {"speed_m_per_s", exact(in.speed_m_per_s)},
                      {"target_depth_m", exact(in.target_depth_m)},
                      {"angle_deg", exact(in.angle_deg)}};
  key["fem"] = {{"refinement", options.refinement >= 0 ? options.refinement : scene.fem.refinement},
                {"element_degree", options.degree >= 1 ? options.degree : scene.fem.element_degree},
                {"load_step_m", exact(scene.fem.load_step_m)},
                {"max_newton_iterations", scene.fem.max_newton_iterations},
                {"newton_tolerance", exact(scene.fem.newton_tolerance)}};
#ifdef PUNCTURE_HAVE_FEM
  key["mesh"] = {{"elements_through_skin", options.mesh.elements_through_skin},
                 {"radial_grading", exact(options.mesh.radial_grading)},
                 {"sectors", options.mesh.sectors},
                 {"thickness_grading", exact(options.mesh.thickness_grading)}};
#endif
  return key.dump(2) + "\n";
}

/// A complete reference: the summary says it finished and the curve exists.
bool reference_complete(const std::filesystem::path& dir, bool need_vtu) {
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

std::string fem_reference_hash(const Scene& scene, const FemReferenceOptions& options) {
  const std::string text = fem_reference_key_text(scene, options);
  // Two FNV-1a 64 passes with different offset bases: a 128-bit key.
  return io::fnv1a64_hex(text) + io::fnv1a64_hex(text, 0x84222325cbf29ce4ULL);
}

#ifdef PUNCTURE_HAVE_FEM
namespace {
std::unique_ptr<dealii::Utilities::MPI::MPI_InitFinalize>& mpi_session() {
  static std::unique_ptr<dealii::Utilities::MPI::MPI_InitFinalize> session;
  return session;
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
  mpi_session().reset();
#endif
}

FemReference obtain_fem_reference(const Scene& scene, const FemReferenceOptions& options, std::ostream& out) {
  FemReference ref;
  ref.hash = fem_reference_hash(scene, options);
  ref.dir = options.cache_dir / ref.hash;
  if (reference_complete(ref.dir, options.write_vtu)) {
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
  try {
    fem::run_needle_insertion(scene, fem_options, MPI_COMM_WORLD);
    if (root) {
      std::ofstream key(staging / "fem_reference_key.json");
      key << fem_reference_key_text(scene, options);
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

}  // namespace puncture::apps
