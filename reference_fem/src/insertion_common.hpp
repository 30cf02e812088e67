// insertion_common.hpp: what the two insertion drivers share
// (axisymmetric_insertion.cc, slab_insertion_run.cc): the state of a layer (the
// core's LayerState), the number format of the CSV files, the rows of the surface and recovery
// profiles, the force-depth CSV's layer-state columns, the checks of the
// scene both drivers make, a layer's long-term law and Prony series, the text
// outputs and the puncture events of the summary. Internal to reference_fem/src (not part of the public headers).
//
// Units: depths, radii and displacements in m in, mm in the CSV files;
// forces in N; times in s.
#pragma once

#include <cstddef>
#include <filesystem>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <puncture/fem/hyperelastic_materials.hpp>
#include <puncture/fem/needle_insertion.hpp>
#include <puncture/fem/viscoelastic_material.hpp>
#include <puncture/io/atomic_file.hpp>
#include <puncture/puncture_force.hpp>
#include <puncture/scene.hpp>

namespace puncture::fem::insertion {

/// What the needle has done to a layer so far: the real-time model's
/// LayerState (puncture_force.hpp), written with its to_string.
using puncture::LayerState;

/// The layer's long-term law: its material, scaled by the relaxed fraction
/// g_inf when the scene's modulus is the instantaneous one (nu kept, so the
/// bulk modulus scales with it).
inline LayerMaterial long_term_material(const ContinuumMaterial& m) {
  const Viscoelasticity& v = m.viscoelastic;
  if (!v.enabled() || v.modulus_basis == Viscoelasticity::ModulusBasis::LongTerm) return LayerMaterial(m);
  ContinuumMaterial relaxed = m;
  relaxed.youngs_modulus_Pa *= v.relaxed_fraction();
  return LayerMaterial(relaxed);
}

/// The layer's Prony series in the solvers' form (beta_i relative to the long-term law).
inline std::vector<PronyTerm> prony_terms(const Viscoelasticity& v) {
  std::vector<NormalisedPronyTerm> normalised;
  for (const PronyRelaxationTerm& t : v.terms) normalised.push_back({t.g, t.tau_s});
  return prony_terms_from_normalised(normalised);
}

/// `v` with `precision` significant digits (the number format of every CSV).
inline std::string format_double(double v, int precision = 9) {
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

/// u_z(r) of a surface: pairs (r, u_z), both in m.
using SurfaceProfile = std::vector<std::pair<double, double>>;

/// The three text records a run collects while it walks: the Newton tables,
/// the surface profile of the pressed layer, the spring-back of punctured
/// surfaces (CSV headers already in place).
struct InsertionRecords {
  std::ostringstream newton_log, profile_csv, recovery_csv;
  InsertionRecords() {
    profile_csv << "step,depth_mm,r_mm,uz_mm,surface\n";
    recovery_csv << "layer,phase,depth_mm,r_mm,uz_mm\n";
  }

  /// Rows `step,depth_mm,r_mm,uz_mm,surface` of fem_surface_profile.csv.
  void add_surface_profile(int step, double depth_m, const SurfaceProfile& profile, const std::string& surface) {
    for (const auto& [r, uz] : profile)
      profile_csv << step << "," << format_double(depth_m * 1e3) << "," << format_double(r * 1e3) << ","
                  << format_double(uz * 1e3) << "," << surface << "\n";
  }

  /// Rows `layer,phase,depth_mm,r_mm,uz_mm` of fem_recovery_profile.csv
  /// (phase "before" or "after" the breakthrough).
  void add_recovery_profile(std::size_t layer, const char* phase, double depth_m, const SurfaceProfile& profile) {
    for (const auto& [r, uz] : profile)
      recovery_csv << layer << "," << phase << "," << format_double(depth_m * 1e3) << ","
                   << format_double(r * 1e3) << "," << format_double(uz * 1e3) << "\n";
  }
};

/// Header line of fem_force_depth.csv: `columns`, then `<layer>_state` per layer.
inline std::string force_depth_header(const std::string& columns, const Scene& scene) {
  std::string header = columns;
  for (const auto& layer : scene.layers) header += "," + layer.name + "_state";
  return header + "\n";
}

/// The `<layer>_state` columns of one row of fem_force_depth.csv.
inline void append_layer_states(std::ostream& csv, const std::vector<LayerState>& states) {
  for (const auto s : states) csv << "," << to_string(s);
}

/// The checks of the scene both references make (layers, an insertion at
/// positive speed); throws std::invalid_argument.
inline void check_insertion(const Scene& scene) {
  if (scene.layers.empty()) throw std::invalid_argument("fem: the scene has no layers");
  if (!(scene.insertion.speed_m_per_s > 0.0)) throw std::invalid_argument("fem: insertion speed must be > 0");
}

/// check_insertion, and an insertion along the sample axis (the axisymmetric reference).
inline void check_axial_insertion(const Scene& scene) {
  check_insertion(scene);
  if (scene.insertion.angle_deg != 0.0)
    throw std::invalid_argument("fem: the axisymmetric reference inserts along the sample axis only (angle_deg = 0); "
                                "the 3d reference (a blunt tip) takes an angle");
}

/// Element degree: the option's override, else the scene's.
inline int element_degree(const Scene& scene, const FemRunOptions& options) {
  return options.degree_override > 0 ? options.degree_override : scene.fem.element_degree;
}

/// Global refinements: the option's override, else the scene's.
inline int refinement_level(const Scene& scene, const FemRunOptions& options) {
  return options.refinement_override >= 0 ? options.refinement_override : scene.fem.refinement;
}

/// Writes fem_force_depth.csv (`force_depth_csv`), the two profiles and the
/// Newton log into `out_dir`, each atomically.
inline void write_text_outputs(const std::filesystem::path& out_dir, const std::string& force_depth_csv,
                               const InsertionRecords& records) {
  io::write_file_atomically(out_dir / "fem_force_depth.csv", force_depth_csv);
  io::write_file_atomically(out_dir / "fem_surface_profile.csv", records.profile_csv.str());
  io::write_file_atomically(out_dir / "fem_recovery_profile.csv", records.recovery_csv.str());
  io::write_file_atomically(out_dir / "fem_newton_log.txt", records.newton_log.str());
}

/// Appends the names of the text outputs and of fem_summary.json to `files`.
inline void list_text_outputs(std::vector<std::string>& files) {
  for (const char* f : {"fem_force_depth.csv", "fem_surface_profile.csv", "fem_recovery_profile.csv",
                        "fem_newton_log.txt", "fem_summary.json"})
    files.push_back(f);
}

/// The summary's "punctures" array (depths in mm; `max_stretch` when
/// `with_stretch`, as the 3D reference reports it).
inline nlohmann::json punctures_json(const std::vector<PunctureEvent>& events, bool with_stretch) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : events) {
    nlohmann::json j = {{"layer", e.layer},     {"name", e.layer_name},           {"depth_mm", e.depth_m * 1e3},
                        {"force_N", e.force_N}, {"force_after_N", e.force_after_N}, {"time_s", e.time_s}};
    if (with_stretch) j["max_stretch"] = e.max_stretch;
    out.push_back(j);
  }
  return out;
}

/// The fields of fem_summary.json both drivers write: the run's status, its
/// scene, the discretisation (dofs, cells, element degree, refinement, load
/// step in mm), the peak force, the step and Newton counts, the timings, the
/// warnings, the punctures (with the tip's stretch when `with_stretch`) and
/// the files. Each driver adds its own fields to the object this returns.
inline nlohmann::json common_summary_json(const std::string& status, const std::string& scene_name,
                                          const FemRunSummary& summary, int element_degree, int refinement,
                                          double load_step_m, bool with_stretch) {
  nlohmann::json j;
  j["status"] = status;
  j["scene"] = scene_name;
  j["n_dofs"] = summary.n_dofs;
  j["n_cells"] = summary.n_cells;
  j["element_degree"] = element_degree;
  j["refinement"] = refinement;
  j["load_step_mm"] = load_step_m * 1e3;
  j["peak_force_N"] = summary.peak_force_N;
  j["peak_force_depth_mm"] = summary.peak_force_depth_m * 1e3;
  j["load_steps"] = summary.load_steps;
  j["step_cuts"] = summary.step_cuts;
  j["newton_iterations"] = summary.newton_iterations;
  j["wall_time_s"] = summary.wall_time_s;
  j["solve_time_s"] = summary.solve_time_s;
  j["warnings"] = summary.warnings;
  j["punctures"] = punctures_json(summary.punctures, with_stretch);
  j["files"] = summary.files_written;
  return j;
}

}  // namespace puncture::fem::insertion
