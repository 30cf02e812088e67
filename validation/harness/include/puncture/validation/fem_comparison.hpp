// fem_comparison.hpp: the real-time model against the FEM reference's files
// (used by `puncture validate` and `puncture sweep`).
//
//   read_fem_result(dir, scene)      the FEM reference files of one cache entry:
//                                    curve, summary, surface profiles per layer,
//                                    spring-back profiles, VTK frames
//   RingRecorder                     ring deflections Delta Z_j (m, > 0 into the
//                                    tissue) of every layer at every haptic tick
//   compare_layer_deflection(...)    Delta Z_j against the FEM u_z before and
//                                    after a layer's breakthrough
//   fem_deflection_at_mm(...)        FEM deflection of a layer's top surface at
//                                    radius r and time t (for error fields)
//   run_plot_script(name, dir, ...)  /usr/bin/python3 scripts/<name> <dir>
//   validation_summary_markdown(...) validation_summary.md
//   layer_metrics_csv, deflection_profiles_csv, aligned_curves_csv,
//   validation_metrics_json          the report files of `puncture validate`
#pragma once

#include <filesystem>
#include <iosfwd>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "puncture/io/provenance.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/scene.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::validation {

/// Which FEM reference a report compares with.
struct FemReferenceInfo {
  std::string hash;         ///< cache key
  bool from_cache = false;  ///< read from the cache (true) or computed by this run
};


struct FemFrame {
  double time_s = 0.0;
  std::string pvtu;                ///< relative to the reference directory
  std::vector<std::string> files;  ///< pvtu and its pieces, relative to the reference directory
};

struct FemResultFiles {
  InsertionCurve curve;  ///< fem_force_depth.csv
  nlohmann::json summary;            ///< fem_summary.json
  /// fem_surface_profile.csv split by the surface (layer name) column, depth order.
  std::map<std::string, std::vector<RadialProfile>> profiles;
  /// fem_recovery_profile.csv: the layer's top surface just before and just
  /// after its breakthrough (same depth), by layer name.
  std::map<std::string, RadialProfile> before_breakthrough, after_breakthrough;
  std::map<std::string, double> puncture_depth_m;  ///< from fem_summary.json
  std::vector<FemFrame> frames;                    ///< from fem_fields.pvd (empty without VTU)
  std::vector<double> frame_times_s;
};
FemResultFiles read_fem_result(const std::filesystem::path& dir, const Scene& scene);

/// FEM deflection (mm, > 0 into the tissue) of layer `layer`'s top surface at
/// radius r_m at time time_s (tip depth = speed t - start height), from the
/// surface profile within half a load step of that depth; NaN if the FEM has
/// no profile of that layer there.
double fem_deflection_at_mm(const FemResultFiles& fem, const Scene& scene, std::size_t layer, double r_m,
                            double time_s);

class RingRecorder {
 public:
  explicit RingRecorder(const Scene& scene);
  /// Appends the current ring deflections of every layer (call once per tick).
  void record(const PunctureSimulator& sim);
  std::size_t ticks() const { return ticks_; }
  /// Delta Z_j, j = 1..w, of layer k at recorded tick i (m, > 0 into the tissue).
  std::vector<double> rings(std::size_t tick, std::size_t layer) const;

 private:
  std::vector<int> rings_per_layer_;
  std::vector<std::size_t> offset_;
  std::size_t stride_ = 0;
  std::size_t ticks_ = 0;
  std::vector<double> data_;
};

struct LayerDeflectionComparison {
  bool compared = false;
  double realtime_depth_m = std::numeric_limits<double>::quiet_NaN();  ///< tip depth of the tick used
  double fem_depth_m = std::numeric_limits<double>::quiet_NaN();       ///< depth of the FEM profile used
  std::vector<double> realtime_rings_m;
  RadialProfile fem;
  DeflectionProfileError error;

  bool recovery_compared = false;
  double recovery_delay_s = std::numeric_limits<double>::quiet_NaN();  ///< time after the real-time breakthrough
  double recovery_realtime_depth_m = std::numeric_limits<double>::quiet_NaN();  ///< tip depth then
  std::vector<double> realtime_recovered_rings_m;
  RadialProfile fem_after;
  DeflectionProfileError recovery_error;
};

/// Before breakthrough: the last insertion depth at which layer k is intact in
/// both models (the smaller of the two pre-breakthrough depths); the real-time
/// Delta Z_j at that tick against the FEM profile of the layer at that depth
/// (linear between the two recorded load steps that bracket it). After: the FEM spring-back profile against the real-time rings
/// ceil(resumption time x haptic rate) ticks after the real-time breakthrough
/// (the layer's resumption_time_s, when Eq. 8's recovery factor has reached 0),
/// or the last tick before layer k + 1 breaks if that comes first (the FEM's
/// profile after the break is taken before the next layer breaks).
LayerDeflectionComparison compare_layer_deflection(const Scene& scene, std::size_t k, const ScriptedRunResult& run,
                                                   const RingRecorder& recorder, const FemResultFiles& fem);

/// Runs /usr/bin/python3 (else python3) <source>/scripts/<script> <dir>; a
/// failure is reported on `err` as a warning. Returns the *.png file names in
/// dir afterwards (sorted).
std::vector<std::string> run_plot_script(const std::string& script, const std::filesystem::path& dir,
                                         std::ostream& out, std::ostream& err);

/// acceptance_section: markdown (acceptance.hpp) placed after the force table.
std::string validation_summary_markdown(const Scene& scene, const io::Provenance& provenance,
                                        const FemReferenceInfo& reference, const FemResultFiles& fem,
                                        const CurveComparison& cmp, const nlohmann::json& layers,
                                        const std::vector<std::string>& plots, bool has_vtk,
                                        const std::string& acceptance_section = "");

/// layer_metrics.csv: per-layer force, puncture and deflection metrics.
std::string layer_metrics_csv(const Scene& scene, const CurveComparison& cmp,
                              const std::vector<LayerDeflectionComparison>& deflection, const io::Provenance& provenance);
/// deflection_profiles.csv: deflection (mm, > 0 into the tissue) against the
/// distance from the needle axis, both models, before and after breakthrough.
std::string deflection_profiles_csv(const Scene& scene, const std::vector<LayerDeflectionComparison>& deflection,
                                    const io::Provenance& provenance);
/// force_depth_aligned.csv: the FEM's insertion samples with the real-time
/// force interpolated at the same depths.
std::string aligned_curves_csv(const InsertionCurve& realtime, const InsertionCurve& fem,
                               const io::Provenance& provenance);
/// Per-layer metrics as JSON (the "layers" array of validation_metrics.json).
nlohmann::json layer_metrics_json(const Scene& scene, const CurveComparison& cmp,
                                  const std::vector<LayerDeflectionComparison>& deflection);

}  // namespace puncture::validation
