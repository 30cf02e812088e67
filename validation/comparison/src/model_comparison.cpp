// model_comparison.cpp: runs of the comparison models along the scene's
// insertion and their metrics against the reference; see model_comparison.hpp.
#include "puncture/validation/model_comparison.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "puncture/cutting.hpp"
#include "puncture/needle.hpp"
#include "puncture/puncture_force.hpp"
#include "puncture/shaft_forces.hpp"

namespace puncture::validation {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double elapsed_s(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}
}  // namespace

double quantile(std::vector<double> values, double p) {
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const double position = std::clamp(p, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(position));
  const std::size_t hi = std::min(values.size() - 1, lo + 1);
  return values[lo] + (position - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

namespace {

/// The shaft forces of the force law, the same for every compared model: the
/// rule of the haptic tick (core shaft_forces.hpp) on the model's layer
/// states and contacts, with friction state and crack fronts kept here. A
/// layer is met at the tip when the layer above breaks with the tip below its
/// rest surface (without layer interaction).
class ShaftForcesOfModel {
 public:
  explicit ShaftForcesOfModel(const Scene& scene)
      : scene_(scene), friction_(scene.layers.size()), front_m_(scene.layers.size(), 0.0),
        break_m_(scene.layers.size(), 0.0), release_N_(scene.layers.size(), 0.0),
        release_length_m_(scene.layers.size(), 0.0),
        met_at_break_(scene.layers.size(), 0) {
    if (scene.effects.friction)
      for (std::size_t k = 0; k < scene.layers.size(); ++k)
        friction_[k].emplace(scene.layers[k].force_law.friction, scene.layers[k].material.viscoelastic);
  }

  /// Friction, damping and cutting (N) after the model's step to `needle`.
  double force_N(const comparison::ComparisonModel& model, const std::vector<LayerState>& states,
                 const NeedleState& needle) {
    const std::size_t n_layers = states.size();
    double post = 0.0;
    std::size_t punctured = 0;  // layers punctured from the top
    for (std::size_t k = 0; k < n_layers; ++k) {
      if (states[k] == LayerState::Punctured && punctured == k) ++punctured;
      if (states[k] != LayerState::Punctured) continue;
      const LayerShaftForce f =
          punctured_layer_shaft_force(scene_.layer_top_depth_m(k), scene_.layers[k].thickness_m,
                                      friction_[k] ? &*friction_[k] : nullptr, scene_.effects.damping,
                                      scene_.layers[k].damping_N_s_per_m2, needle);
      post += f.friction_N + f.damping_N;
    }
    const double tip_axial_m = needle.tip_position_m.dot(needle.direction);
    const double v = needle.axial_velocity_m_per_s;
    deepest_m_ = std::max(deepest_m_, tip_axial_m);
    for (std::size_t k = punctured_before_; k < punctured; ++k) {
      // The crack above still cut at the break (k met at the tip; the one
      // just opened at the tip in a chain of breaks) passes its load to k's.
      double crack_above_N = 0.0;
      if (k > 0 && scene_.effects.cutting)
        crack_above_N = k > punctured_before_
                            ? rate_cutting_force(scene_.layers[k - 1].force_law, v).total_N()
                            : open_crack_force_N(scene_.layers[k - 1].force_law, front_m_[k - 1], tip_axial_m, v,
                                                 met_at_break_[k] ? NextLayerContact::MetAtTip : NextLayerContact::Touched)
                                  .total_N();
      front_m_[k] = tip_axial_m;
      break_m_[k] = tip_axial_m;
      release_N_[k] = rupture_release_N(scene_.layers[k].force_law, model.break_force_N(k) + crack_above_N, v);
      release_length_m_[k] = rupture_release_length_m(scene_.layers[k].force_law, v);
      if (k + 1 < n_layers && !scene_.effects.layer_interaction && needle.depth_m() > scene_.layer_top_depth_m(k + 1))
        met_at_break_[k + 1] = 1;
    }
    punctured_before_ = std::max(punctured_before_, punctured);
    if (scene_.effects.cutting && punctured > 0) {
      const NextLayerContact next = punctured == n_layers || !model.layer_touched(punctured) ? NextLayerContact::None
                                    : met_at_break_[punctured]                               ? NextLayerContact::MetAtTip
                                                                                             : NextLayerContact::Touched;
      post += open_crack_force_N(scene_.layers[punctured - 1].force_law, front_m_[punctured - 1], tip_axial_m, v, next)
                  .total_N();
      for (std::size_t k = 0; k < punctured; ++k) {
        const ForceLaw& law = scene_.layers[k].force_law;
        post += rupture_release_force_N(release_N_[k], release_length_m_[k], law.cutting_release_m, break_m_[k],
                                        deepest_m_, tip_axial_m);
      }
    }
    return post;
  }

 private:
  const Scene& scene_;
  std::vector<std::optional<LayerShaftFriction>> friction_;
  std::vector<double> front_m_;
  std::vector<double> break_m_, release_N_, release_length_m_;  ///< rupture release per layer (cutting.hpp)
  double deepest_m_ = -std::numeric_limits<double>::infinity();
  std::vector<char> met_at_break_;
  std::size_t punctured_before_ = 0;
};

/// One sample of the deformed mesh's inverted tetrahedra into the run's worst case.
void record_inversion(const comparison::ElementInversion& sample, double depth_m, ModelRun& run) {
  if (sample.elements == 0) return;  // no tetrahedral mesh
  if (run.inverted_elements_max < 0 || sample.inverted > run.inverted_elements_max) {
    run.inverted_elements_max = sample.inverted;
    run.inverted_share_max = sample.inverted_share();
  }
  if (sample.inverted > 0 && !std::isfinite(run.first_inversion_depth_m)) run.first_inversion_depth_m = depth_m;
  if (std::isnan(run.min_volume_ratio) || sample.min_volume_ratio < run.min_volume_ratio)
    run.min_volume_ratio = sample.min_volume_ratio;
}

}  // namespace

ModelRun run_comparison_model(comparison::ComparisonModel& model, const Scene& scene, const ModelRunOptions& options) {
  ModelRun run;
  run.model = model.name();
  run.description = model.description();
  const ScriptedTrajectory trajectory(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  const double end = options.end_time_s > 0.0 ? std::min(options.end_time_s, trajectory.duration()) : trajectory.duration();
  const long n_steps = static_cast<long>(std::ceil(end / dt - 1e-9)) + 1;
  std::vector<double> profile_depths = options.profile_depths_m;
  std::sort(profile_depths.begin(), profile_depths.end());
  std::size_t next_profile = 0;
  int next_frame = 0;
  long next_progress = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t n_layers = scene.layers.size();
  ShaftForcesOfModel shaft(scene);
  for (long i = 0; i < n_steps; ++i) {
    const double t = static_cast<double>(i) * dt;
    const NeedleState needle = trajectory.sample(t);
    double force = 0.0;
    const auto step_start = std::chrono::steady_clock::now();
    try {
      force = model.step(needle);
    } catch (const std::exception& e) {
      run.failure = std::string("at t = ") + std::to_string(t) + " s: " + e.what();
      break;
    }
    run.step_wall_time_s.push_back(elapsed_s(step_start));
    run.time_s.push_back(t);
    run.depth_m.push_back(needle.depth_m());
    run.velocity_m_per_s.push_back(needle.axial_velocity_m_per_s);
    run.contact_force_N.push_back(force);
    std::vector<LayerState> states(n_layers);
    for (std::size_t k = 0; k < n_layers; ++k) states[k] = model.layer_state(k);
    const double post = shaft.force_N(model, states, needle);
    run.states.push_back(states);
    run.post_puncture_force_N.push_back(post);
    while (next_profile < profile_depths.size() && needle.axial_velocity_m_per_s > 0.0 &&
           needle.depth_m() >= profile_depths[next_profile] - 1e-12) {
      SurfaceSnapshot snapshot;
      snapshot.depth_m = profile_depths[next_profile];  // taken at most one step of needle travel later
      snapshot.r_m = options.profile_radii_m;
      snapshot.deflection_m = model.surface_deflection_m(0, options.profile_radii_m);
      run.skin_profiles.push_back(snapshot);
      ++next_profile;
    }
    if (options.measure_inversion && (i % kInversionSampleSteps == 0 || i + 1 == n_steps))
      record_inversion(model.element_inversion(), needle.depth_m(), run);
    if (options.on_frame && options.frame_interval_s > 0.0 && t + 0.5 * dt >= next_frame * options.frame_interval_s) {
      options.on_frame(model, t, next_frame);
      ++next_frame;
    }
    if (options.on_progress && i >= next_progress) {
      options.on_progress(static_cast<double>(i) / static_cast<double>(n_steps));
      next_progress += std::max(1L, n_steps / 20);
    }
  }
  run.run_wall_time_s = elapsed_s(start);
  run.size = model.model_size();
  run.recovered_steps = model.recovered_steps();
  run.integrator_report = model.integrator_report();
  if (options.on_progress) options.on_progress(1.0);
  return run;
}

InsertionCurve curve_from_model_run(const Scene& scene, const ModelRun& run, bool include_post_puncture) {
  InsertionCurve curve;
  curve.source = run.model;
  curve.metadata["model"] = run.model;
  curve.metadata["force"] =
      include_post_puncture ? "contact + shaft forces (cutting, Karnopp friction, Table 1 d h v)" : "contact";
  curve.time_s = run.time_s;
  curve.depth_m = run.depth_m;
  curve.velocity_m_per_s = run.velocity_m_per_s;
  curve.force_N = run.contact_force_N;
  if (include_post_puncture)
    for (std::size_t i = 0; i < curve.force_N.size(); ++i) curve.force_N[i] += run.post_puncture_force_N[i];
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    curve.layer_names.push_back(scene.layers[k].name);
    std::vector<LayerState> states;
    for (const auto& row : run.states) states.push_back(row[k]);
    curve.layer_states.push_back(states);
  }
  return curve;
}

namespace {

/// First depth of the insertion phase at which the curve's layer is punctured.
double puncture_depth(const InsertionCurve& curve, const std::string& layer) {
  const int k = curve.layer_index(layer);
  if (k < 0) return kNaN;
  for (std::size_t i = 0; i < curve.size(); ++i) {
    if (curve.velocity_m_per_s[i] <= 0.0) continue;
    if (curve.layer_states[static_cast<std::size_t>(k)][i] == LayerState::Punctured) return curve.depth_m[i];
  }
  return kNaN;
}

/// Force RMSE over the reference's withdrawal samples (velocity < 0), the
/// model interpolated at the same depth on its own withdrawal branch.
double withdrawal_rmse(const InsertionCurve& model, const InsertionCurve& reference) {
  auto branch = [](const InsertionCurve& c, std::vector<double>& depth, std::vector<double>& force) {
    std::vector<std::pair<double, double>> pts;
    for (std::size_t i = 0; i < c.size(); ++i)
      if (c.velocity_m_per_s[i] < 0.0) pts.emplace_back(c.depth_m[i], c.force_N[i]);
    std::sort(pts.begin(), pts.end());
    for (const auto& [d, f] : pts)
      if (depth.empty() || d > depth.back()) depth.push_back(d), force.push_back(f);
  };
  std::vector<double> md, mf, rd, rf;
  branch(model, md, mf);
  branch(reference, rd, rf);
  if (md.size() < 2 || rd.empty()) return kNaN;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < rd.size(); ++i) {
    double f = 0.0;
    if (!interpolate_linear(md, mf, rd[i], f)) continue;
    sum += (f - rf[i]) * (f - rf[i]);
    ++n;
  }
  return n ? std::sqrt(sum / static_cast<double>(n)) : kNaN;
}

}  // namespace

namespace {

/// Force RMSE against the reference (both on the loading phase), the peak
/// forces and the withdrawal RMSE.
void add_force_metrics(const InsertionCurve& curve, const ReferenceData& reference, ModelMetrics& m) {
  try {
    const CurveComparison cmp = compare_curves(curve, reference.curve);
    if (cmp.n_compared > 0) {
      m.compared_samples = cmp.n_compared;
      m.force_rmse_N = cmp.force_rmse_N;
      m.force_rmse_relative = cmp.force_rmse_relative;
      m.reference_peak_force_N = cmp.reference_peak_force_N;
    }
  } catch (const std::exception&) {
    // a curve without an insertion phase: the metrics stay n/a
  }
  double model_peak = 0.0, reference_peak = 0.0;
  for (std::size_t i = 0; i < curve.size(); ++i)
    if (curve.velocity_m_per_s[i] > 0.0) model_peak = std::max(model_peak, curve.force_N[i]);
  for (std::size_t i = 0; i < reference.curve.size(); ++i)
    if (reference.curve.velocity_m_per_s[i] > 0.0) reference_peak = std::max(reference_peak, reference.curve.force_N[i]);
  m.model_peak_force_N = model_peak;
  if (reference_peak > 0.0) {
    m.reference_peak_force_N = reference_peak;
    m.peak_force_error_relative = (model_peak - reference_peak) / reference_peak;
  }
  m.withdrawal_force_rmse_N = withdrawal_rmse(curve, reference.curve);
}

/// Each layer's puncture depth in the model and the reference; the mean
/// error over the layers both puncture.
void add_puncture_metrics(const Scene& scene, const InsertionCurve& curve, const ReferenceData& reference,
                          ModelMetrics& m) {
  double depth_error_sum = 0.0;
  int both = 0;
  for (const Layer& layer : scene.layers) {
    LayerPunctureComparison p;
    p.layer = layer.name;
    p.reference_depth_m = puncture_depth(reference.curve, layer.name);
    p.model_depth_m = puncture_depth(curve, layer.name);
    p.reference_punctured = std::isfinite(p.reference_depth_m);
    p.model_punctured = std::isfinite(p.model_depth_m);
    if (p.reference_punctured && p.model_punctured) {
      depth_error_sum += std::abs(p.model_depth_m - p.reference_depth_m);
      ++both;
    } else if (p.reference_punctured != p.model_punctured) {
      ++m.puncture_layers_disagreeing;
    }
    m.punctures.push_back(p);
  }
  if (both > 0) m.puncture_depth_error_m = depth_error_sum / both;
}

/// Skin deflection u_z(r) against the reference's while the skin is intact
/// in both (m.punctures filled).
void add_deflection_metrics(const ModelRun& run, const ReferenceData& reference, ModelMetrics& m) {
  const double skin_limit = std::min(std::isfinite(m.punctures[0].reference_depth_m) ? m.punctures[0].reference_depth_m : 1e300,
                                     std::isfinite(m.punctures[0].model_depth_m) ? m.punctures[0].model_depth_m : 1e300);
  double sq = 0.0, max_ref = 0.0;
  std::size_t n = 0;
  for (const SurfaceSnapshot& s : run.skin_profiles) {
    if (!(s.depth_m > 0.0) || s.depth_m >= skin_limit) continue;
    const RadialProfile* ref = nullptr;
    for (const RadialProfile& p : reference.skin_profiles)
      if (std::abs(p.depth_m - s.depth_m) < 1e-6) ref = &p;
    if (!ref) continue;
    bool used = false;
    for (std::size_t i = 0; i < s.r_m.size(); ++i) {
      double uz = 0.0;
      if (!std::isfinite(s.deflection_m[i]) || !interpolate_linear(ref->r_m, ref->uz_m, s.r_m[i], uz)) continue;
      sq += (s.deflection_m[i] + uz) * (s.deflection_m[i] + uz);  // deflection = -u_z
      max_ref = std::max(max_ref, std::abs(uz));
      ++n;
      used = true;
    }
    if (used) ++m.deflection_depths;
  }
  if (n > 0) {
    m.deflection_rmse_m = std::sqrt(sq / static_cast<double>(n));
    if (max_ref > 0.0) m.deflection_rmse_relative = m.deflection_rmse_m / max_ref;
  }
}

/// Mean, p99 and largest wall time of the steps with the tip in the tissue.
void add_step_time_metrics(const ModelRun& run, ModelMetrics& m) {
  std::vector<double> in_tissue;
  for (std::size_t i = 0; i < run.steps(); ++i)
    if (run.depth_m[i] > 0.0) in_tissue.push_back(run.step_wall_time_s[i]);
  if (in_tissue.empty()) return;
  double sum = 0.0;
  for (double t : in_tissue) sum += t;
  m.step_time_mean_s = sum / static_cast<double>(in_tissue.size());
  m.step_time_p99_s = quantile(in_tissue, 0.99);
  m.step_time_max_s = *std::max_element(in_tissue.begin(), in_tissue.end());
}

}  // namespace

ModelMetrics metrics_against_reference(const Scene& scene, const ModelRun& run, const ReferenceData& reference,
                                       std::size_t total_steps) {
  ModelMetrics m;
  m.model = run.model;
  m.completed_fraction = total_steps ? static_cast<double>(run.steps()) / static_cast<double>(total_steps) : 0.0;
  m.memory_bytes = static_cast<double>(run.size.memory_bytes);
  m.dofs = run.size.dofs;
  if (run.inverted_elements_max >= 0) {
    m.inverted_share_max = run.inverted_share_max;
    m.first_inversion_depth_m = run.first_inversion_depth_m;
    m.min_volume_ratio = run.min_volume_ratio;
  }
  if (run.steps() < 2) return m;
  const InsertionCurve curve = curve_from_model_run(scene, run, reference.has_shaft_forces);
  add_force_metrics(curve, reference, m);
  add_puncture_metrics(scene, curve, reference, m);
  add_deflection_metrics(run, reference, m);
  add_step_time_metrics(run, m);
  return m;
}

}  // namespace puncture::validation
