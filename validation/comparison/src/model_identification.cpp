// model_identification.cpp: stiffness factors and critical forces of a
// comparison model against the reference; see model_identification.hpp.
#include "puncture/validation/model_identification.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>

#include "puncture/comparison/model_factory.hpp"
#include "puncture/comparison/sparse_spd_factor.hpp"
#include "puncture/needle.hpp"
#include "puncture/validation/levenberg_marquardt.hpp"
#include "puncture/validation/puncture_events.hpp"

namespace puncture::validation {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Time (s) of the first haptic step at which the scripted tip reaches depth_m; < 0 if never.
double first_step_at_depth(const Scene& scene, double depth_m) {
  const ScriptedTrajectory trajectory(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  for (long i = 0; i * dt <= trajectory.duration() + 1e-12; ++i)
    if (trajectory.sample(i * dt).depth_m() >= depth_m) return i * dt;
  return -1.0;
}

void set_critical_force(Scene& scene, std::size_t layer, double force_N) {
  BreakthroughCriterion& b = scene.layers[layer].force_law.breakthrough;
  b.kind = BreakthroughCriterion::Kind::CriticalForce;
  b.critical_force_N = force_N;
}

/// The model on `scene` until `until_s` (layer k's rule: never breaks).
ModelRun run_until(const std::string& model, const Scene& scene, std::shared_ptr<const meshing::TetMesh> mesh,
                   double until_s) {
  std::unique_ptr<comparison::ComparisonModel> m =
      comparison::make_comparison_model(model, scene, comparison::is_volumetric_model(model) ? mesh : nullptr);
  ModelRunOptions options;
  options.end_time_s = until_s;
  return run_comparison_model(*m, scene, options);
}

/// A run's contact and shaft force at a depth of its insertion (linear in depth between steps); false outside.
bool forces_at_depth(const ModelRun& run, double depth_m, double& contact_N, double& shaft_N) {
  for (std::size_t i = 1; i < run.steps(); ++i) {
    if (!(run.velocity_m_per_s[i] > 0.0) || run.depth_m[i] < depth_m || run.depth_m[i - 1] > depth_m) continue;
    const double span = run.depth_m[i] - run.depth_m[i - 1];
    const double t = span > 0.0 ? (depth_m - run.depth_m[i - 1]) / span : 1.0;
    contact_N = run.contact_force_N[i - 1] + t * (run.contact_force_N[i] - run.contact_force_N[i - 1]);
    shaft_N = run.post_puncture_force_N[i - 1] + t * (run.post_puncture_force_N[i] - run.post_puncture_force_N[i - 1]);
    return true;
  }
  return false;
}

/// The reference's samples of a window [from, to) of the insertion: depth
/// (m) and the force the model's contact force is compared with (N: the
/// reference's force less the model's shaft force where the reference has
/// shaft forces; the shaft forces come from the run at s_k = 1, they do not
/// depend on the pressed layer's modulus).
struct Window {
  std::vector<double> depth_m, target_N;
  double scale_N = 1.0;  ///< residuals are divided by this (the reference's peak force)
};

/// The reference's samples on which layer k's factor is fitted: insertion
/// (loading) samples before the layer's puncture with the layer pressed. With
/// state columns (the FEM's curve) "pressed" is the layer's state: the
/// layer segments would not do there, as they end the cut through the layer
/// above where the reference's tip force returns to 0, and the FEM's stays
/// positive after the fat's break (the muscle, pressed from 12.2 mm on the
/// default trajectory, had no window), and a depth range would take in the
/// sample before a force drop that shares its depth with the one after it
/// (the quasi-static 3D reference). Without states: the depth range of the
/// layer's pressing segment (layer_segments). Either way a sample that shares
/// its depth with its neighbour (a force drop at one instant: the model's
/// force at that depth is on either side of its own drop) is left out.
struct PressingWindow {
  int state_column = -1;  ///< the layer's state column, -1: none
  double from_m = kNaN, to_m = kNaN;
  bool contains(const InsertionCurve& curve, std::size_t i) const {
    if (!(curve.velocity_m_per_s[i] > 0.0) || !(curve.depth_m[i] < to_m)) return false;
    if ((i > 0 && curve.depth_m[i - 1] == curve.depth_m[i]) ||
        (i + 1 < curve.size() && curve.depth_m[i + 1] == curve.depth_m[i]))
      return false;
    if (state_column >= 0) return curve.layer_states[static_cast<std::size_t>(state_column)][i] == LayerState::Pressed;
    return curve.depth_m[i] >= from_m;
  }
};

PressingWindow pressing_window(const InsertionCurve& curve, const std::string& layer, const LayerSegments& segment,
                               double puncture_m) {
  PressingWindow w;
  w.to_m = puncture_m;
  w.state_column = curve.layer_index(layer);
  if (w.state_column < 0 && segment.has_pressing) w.from_m = segment.pressing_from_m;
  return w;
}

Window window_of(const ModelRun& run, const ReferenceData& reference, const PressingWindow& pressed) {
  Window w;
  const InsertionCurve& curve = reference.curve;
  double peak = 0.0;
  for (std::size_t i = 0; i < curve.size(); ++i) {
    if (!(curve.velocity_m_per_s[i] > 0.0)) continue;
    peak = std::max(peak, std::abs(curve.force_N[i]));
    if (!pressed.contains(curve, i)) continue;
    double contact = 0.0, shaft = 0.0;
    if (!forces_at_depth(run, curve.depth_m[i], contact, shaft)) continue;
    w.depth_m.push_back(curve.depth_m[i]);
    w.target_N.push_back(curve.force_N[i] - (reference.has_shaft_forces ? shaft : 0.0));
  }
  w.scale_N = peak > 0.0 ? peak : 1.0;
  return w;
}

/// The reference's samples in the window (before any model run: a window
/// with fewer than two is not fitted, and its run is saved).
std::size_t reference_samples_in(const ReferenceData& reference, const PressingWindow& pressed) {
  const InsertionCurve& curve = reference.curve;
  std::size_t n = 0;
  for (std::size_t i = 0; i < curve.size(); ++i) n += pressed.contains(curve, i);
  return n;
}

/// (model contact force - target) / scale at the window's depths; false if a depth is not reached.
bool window_residuals(const ModelRun& run, const Window& w, std::vector<double>& r) {
  r.resize(w.depth_m.size());
  for (std::size_t i = 0; i < w.depth_m.size(); ++i) {
    double contact = 0.0, shaft = 0.0;
    if (!forces_at_depth(run, w.depth_m[i], contact, shaft)) return false;
    r[i] = (contact - w.target_N[i]) / w.scale_N;
  }
  return true;
}

double rmse_N(const std::vector<double>& r, double scale_N) {
  double sum = 0.0;
  for (double x : r) sum += x * x;
  return r.empty() ? kNaN : scale_N * std::sqrt(sum / r.size());
}

/// The optimiser's settings of every factor fit (ln s, full model runs, two at a time).
LevenbergMarquardtOptions factor_fit_options(int max_evaluations) {
  LevenbergMarquardtOptions options;
  options.max_iterations = 6;
  options.max_evaluations = max_evaluations;
  options.fd_step = options.fd_step_min = 0.02;
  options.cost_tolerance = 1e-3;
  options.step_tolerance = 1e-3;  // a factor to 0.1 %: finer steps move no table (the runs to confirm them did)
  // One step that lowers the windows' cost by less than 0.1 % ends the fit: a
  // second one, to confirm, cost a Jacobian and a trial (3 model runs of
  // 10-20 s each on the default slab) and moved the factor by 0.001 %.
  options.stalls_to_stop = 1;
  // The one-factor fits take the secant through their two trial runs as the
  // next Jacobian instead of a difference run alone (the joint fit, with
  // more factors, does not: secant_jacobian needs one parameter).
  options.secant_jacobian = true;
  options.threads = comparison::concurrent_solver_threads(2);
  return options;
}

/// Layer k's factor: the least-squares factor for a force proportional to
/// the modulus from run A, then Levenberg-Marquardt on ln s_k with the full
/// model (levenberg_marquardt.hpp). Books the runs and the window's RMSE.
double identified_scale(const std::string& model, const Scene& trial, std::size_t k,
                        std::shared_ptr<const meshing::TetMesh> mesh, double until_s, const ModelRun& run_a,
                        const Window& w, LayerIdentification& layer, int& runs,
                        const IdentificationStepProgress& progress) {
  std::vector<double> r;
  window_residuals(run_a, w, r);
  layer.window_samples = r.size();
  layer.window_rmse_before_N = rmse_N(r, w.scale_N);
  double cc = 0.0, cf = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const double c = r[i] * w.scale_N + w.target_N[i];
    cc += c * c, cf += c * w.target_N[i];
  }
  const double proportional = cc > 0.0 && cf > 0.0 ? std::clamp(cf / cc, 1.0 / kStiffnessScaleBound, kStiffnessScaleBound) : 1.0;
  std::mutex progress_mutex;
  int evaluations = 0;
  const ResidualFunction residuals = [&](const std::vector<double>& x, std::vector<double>& out) {
    Scene s = trial;
    s.comparison.stiffness_scale[k] = std::exp(x[0]);
    const bool ok = window_residuals(run_until(model, s, mesh, until_s), w, out);
    if (progress) {
      const std::lock_guard<std::mutex> lock(progress_mutex);
      std::ostringstream line;
      line << layer.layer << ": run " << ++evaluations << " of the optimiser, factor " << std::exp(x[0])
           << ", force RMSE " << (ok ? rmse_N(out, w.scale_N) : kNaN) << " N";
      progress(line.str());
    }
    return ok;
  };
  const LevenbergMarquardtOptions options = factor_fit_options(14);
  const double bound = std::log(kStiffnessScaleBound);
  try {
    const LevenbergMarquardtResult fit =
        levenberg_marquardt(residuals, {std::log(proportional)}, {-bound}, {bound}, options);
    runs += fit.evaluations;
    layer.window_rmse_after_N = rmse_N(fit.residuals, w.scale_N);
    return std::exp(fit.x[0]);
  } catch (const std::exception& e) {  // the model cannot run at the proportional start
    layer.stiffness_note = std::string("stiffness kept: ") + e.what();
    layer.window_rmse_after_N = layer.window_rmse_before_N;
    return 1.0;
  }
}

/// Relative rise of the windows' summed cost, at the bottom-up factors,
/// over the sum of their own fits below which the joint fit stops at its
/// start: no window was moved by the other layers' factors, so there is no
/// coupling for a joint fit to weigh (one run instead of a Jacobian's and
/// trial steps').
constexpr double kJointCouplingTolerance = 0.01;

/// The joint step: ln s of every fitted layer at once (Levenberg-Marquardt
/// from the bottom-up factors) on all their windows, from one run to the
/// deepest fitted layer's puncture (prepare_layer_run of that layer: the
/// layers above break where the reference breaks them, each window sees the
/// same forces as in its own run). own_cost: the sum of the windows' squared
/// residuals in their own bottom-up fits (the fit stops at its start when the
/// joint run's cost is within kJointCouplingTolerance of it). Keeps the
/// factors when the fit does not lower the cost. Returns the note for the report.
std::string joint_refinement(const std::string& model, const Scene& trial, const std::vector<std::size_t>& fitted,
                             const std::vector<Window>& windows, double own_cost,
                             std::shared_ptr<const meshing::TetMesh> mesh, double until_s,
                             std::vector<double>& scale, std::vector<double>& rmse_after_N, int& runs,
                             const IdentificationStepProgress& progress) {
  std::mutex progress_mutex;
  int evaluations = 0;
  const ResidualFunction residuals = [&](const std::vector<double>& x, std::vector<double>& out) {
    Scene s = trial;
    for (std::size_t j = 0; j < fitted.size(); ++j) s.comparison.stiffness_scale[fitted[j]] = std::exp(x[j]);
    const ModelRun run = run_until(model, s, mesh, until_s);
    out.clear();
    bool ok = !run.failed();
    for (std::size_t j = 0; ok && j < fitted.size(); ++j) {
      std::vector<double> r;
      ok = window_residuals(run, windows[j], r);
      out.insert(out.end(), r.begin(), r.end());
    }
    if (progress) {
      const std::lock_guard<std::mutex> lock(progress_mutex);
      std::ostringstream line;
      line << "joint: run " << ++evaluations << " of the optimiser, factors";
      for (double v : x) line << " " << std::exp(v);
      progress(line.str());
    }
    return ok;
  };
  std::vector<double> x0, lower, upper;
  for (std::size_t k : fitted) {
    x0.push_back(std::log(scale[k]));
    lower.push_back(-std::log(kStiffnessScaleBound));
    upper.push_back(std::log(kStiffnessScaleBound));
  }
  LevenbergMarquardtOptions options = factor_fit_options(4 * static_cast<int>(fitted.size()) + 8);
  options.accept_start_cost = (1.0 + kJointCouplingTolerance) * own_cost;
  try {
    const LevenbergMarquardtResult fit = levenberg_marquardt(residuals, x0, lower, upper, options);
    runs += fit.evaluations;
    std::ostringstream note;
    note << "joint fit of the factors of";
    for (std::size_t k : fitted) note << " " << trial.layers[k].name;
    if (fit.status == "start_accepted") {
      note << " not needed: at the bottom-up factors their windows cost " << fit.initial_cost << " together, "
           << own_cost << " in their own fits (within " << 100.0 * kJointCouplingTolerance
           << " %: no window is moved by the other layers' factors; 1 run)";
      return note.str();
    }
    note << " on all their windows (" << fit.evaluations << " runs): sum of squared residuals " << fit.initial_cost
         << " -> " << std::min(fit.cost, fit.initial_cost);
    if (!(fit.cost < fit.initial_cost)) return note.str() + ", bottom-up factors kept";
    std::size_t offset = 0;
    for (std::size_t j = 0; j < fitted.size(); ++j) {
      scale[fitted[j]] = std::exp(fit.x[j]);
      const std::vector<double> r(fit.residuals.begin() + static_cast<long>(offset),
                                  fit.residuals.begin() + static_cast<long>(offset + windows[j].depth_m.size()));
      rmse_after_N[fitted[j]] = rmse_N(r, windows[j].scale_N);
      offset += windows[j].depth_m.size();
    }
    return note.str();
  } catch (const std::exception& e) {  // e.g. the model cannot run at the bottom-up factors
    return std::string("joint fit not run, bottom-up factors kept: ") + e.what();
  }
}

/// Layer k unbreakable, the layers above it broken where the reference breaks them.
void prepare_layer_run(Scene& trial, std::size_t k, const std::vector<double>& depths_m) {
  trial.comparison.prescribed_puncture_depths_m.assign(depths_m.begin(), depths_m.begin() + static_cast<long>(k));
  set_critical_force(trial, k, std::numeric_limits<double>::infinity());
}

}  // namespace

bool near_stiffness_scale_bound(double scale) {
  return scale > 0.0 && std::abs(std::log(scale)) >= std::log(kStiffnessScaleBound) - std::log(1.1);
}

namespace {

// The fitted factors (of `fitted`, top down, each on its window) refined
// jointly: a layer's factor also shapes the force while the layers above it
// are pressed (a volumetric model's skin rests on its fat), which the
// bottom-up pass, each layer on its own window, cannot weigh.
void refine_factors_jointly(const std::string& model, const std::shared_ptr<const meshing::TetMesh>& mesh,
                            const std::vector<double>& depths_m, const std::vector<double>& until_s,
                            const std::vector<std::size_t>& fitted, const std::vector<Window>& fitted_windows,
                            Scene& trial, ModelIdentification& result, const IdentificationStepProgress& progress) {
  const std::size_t deepest = fitted.back();
  prepare_layer_run(trial, deepest, depths_m);
  std::vector<double> rmse_after(trial.layers.size(), kNaN);
  double own_cost = 0.0;  // in the optimiser's units: sum of (residual / window scale)^2
  for (std::size_t j = 0; j < fitted.size(); ++j) {
    const double rmse = result.layers[fitted[j]].window_rmse_after_N / fitted_windows[j].scale_N;
    own_cost += static_cast<double>(fitted_windows[j].depth_m.size()) * rmse * rmse;
  }
  result.joint_note = joint_refinement(model, trial, fitted, fitted_windows, own_cost, mesh, until_s[deepest],
                                       trial.comparison.stiffness_scale, rmse_after, result.model_runs, progress);
  for (std::size_t k : fitted)
    if (std::isfinite(rmse_after[k])) {
      result.layers[k].stiffness_scale = trial.comparison.stiffness_scale[k];
      result.layers[k].window_rmse_after_N = rmse_after[k];
    }
}

// The critical forces, top down, with the final factors: layer k's force
// where the reference breaks it, the layers above broken there too (as their
// own critical forces then do).
void identify_critical_forces(const std::string& model, const std::shared_ptr<const meshing::TetMesh>& mesh,
                              const std::vector<double>& depths_m, const std::vector<double>& until_s, Scene& trial,
                              ModelIdentification& result, const IdentificationStepProgress& progress) {
  for (std::size_t k = 0; k < depths_m.size(); ++k) {
    prepare_layer_run(trial, k, depths_m);
    const ModelRun run = run_until(model, trial, mesh, until_s[k]);
    ++result.model_runs;
    LayerIdentification& layer = result.layers[k];
    const double force = run.failed() || run.steps() == 0 ? 0.0 : run.contact_force_N.back();
    if (!(force > 0.0) || !std::isfinite(force)) {
      layer.note = run.failed() ? "the model run failed: " + run.failure
                                : "the model's contact force is not positive at the reference's puncture depth";
      for (std::size_t j = k; j < depths_m.size(); ++j) result.layers[j].stiffness_scale = 1.0;
      result.layers.resize(k + 1);
      break;
    }
    layer.identified = true;
    layer.critical_force_N = force;
    if (progress) {
      std::ostringstream line;
      line << layer.layer << ": modulus x " << layer.stiffness_scale << ", breaks at " << force << " N";
      progress(line.str());
    }
  }
}

}  // namespace

ModelIdentification identify_comparison_model(const std::string& model, const Scene& scene,
                                              std::shared_ptr<const meshing::TetMesh> mesh,
                                              const ReferenceData& reference, bool identify_stiffness,
                                              const IdentificationStepProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  ModelIdentification result;
  result.model = model;
  result.stiffness_identified = identify_stiffness;
  const std::vector<LayerGeometry> geometry = layer_geometry(scene);
  const ReferenceEvents events = reference_events(reference.curve, geometry);
  const std::vector<LayerSegments> segments = layer_segments(events, geometry);
  // The layers the reference punctures on this trajectory, from the top.
  std::vector<double> depths_m, until_s;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    LayerIdentification layer;
    layer.layer = scene.layers[k].name;
    const PunctureEventMetrics& p = events.punctures[k];
    layer.reference_depth_m = p.found ? p.depth_m : kNaN;
    const double until = p.found ? first_step_at_depth(scene, p.depth_m) : -1.0;
    result.layers.push_back(layer);
    if (until < 0.0) {
      result.layers.back().note = p.found ? "the trajectory does not reach the reference's puncture depth"
                                          : "the reference does not puncture this layer";
      break;  // the layers below are not reached either
    }
    if (!until_s.empty() && until == until_s.back()) {
      // Broken on the haptic step that breaks the layer above: the reference
      // never presses it, the model cannot either (its contact force there is
      // the first touch, not a strength), and the layers below would be
      // fitted for nothing.
      std::ostringstream note;
      note << "the reference punctures it on the haptic step that punctures " << scene.layers[k - 1].name << " ("
           << depths_m.back() * 1e3 << " mm): it is never pressed, so its critical force cannot be identified";
      result.layers.back().note = note.str();
      break;
    }
    depths_m.push_back(p.depth_m);
    until_s.push_back(until);
  }
  Scene trial = scene;
  trial.comparison.stiffness_scale.assign(scene.layers.size(), 1.0);
  std::vector<std::size_t> fitted;  // layers whose factor was fitted, top down
  std::vector<Window> fitted_windows;
  // 1. The factors, bottom up: a layer's force depends on the layers below it
  //    (and hardly on the punctured ones above), whose factors are then known.
  for (std::size_t k = depths_m.size(); identify_stiffness && k-- > 0;) {
    const PressingWindow pressed = pressing_window(reference.curve, scene.layers[k].name, segments[k], depths_m[k]);
    const std::size_t samples = reference_samples_in(reference, pressed);
    if (samples < 2) {  // nothing to fit: the factor stays 1, no run
      result.layers[k].window_samples = samples;
      continue;
    }
    prepare_layer_run(trial, k, depths_m);
    const ModelRun run = run_until(model, trial, mesh, until_s[k]);
    ++result.model_runs;
    const Window window =
        run.failed() ? Window{} : window_of(run, reference, pressed);
    if (window.depth_m.size() < 2) continue;
    LayerIdentification& layer = result.layers[k];
    layer.stiffness_scale =
        identified_scale(model, trial, k, mesh, until_s[k], run, window, layer, result.model_runs, progress);
    trial.comparison.stiffness_scale[k] = layer.stiffness_scale;
    if (layer.stiffness_note.empty()) {
      fitted.insert(fitted.begin(), k);
      fitted_windows.insert(fitted_windows.begin(), window);
    }
  }
  // 1b. The fitted factors jointly (refine_factors_jointly).
  if (fitted.size() >= 2)
    refine_factors_jointly(model, mesh, depths_m, until_s, fitted, fitted_windows, trial, result, progress);
  // 2. The critical forces, top down, with the final factors (identify_critical_forces).
  identify_critical_forces(model, mesh, depths_m, until_s, trial, result, progress);
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

Scene with_identified_parameters(const Scene& scene, const ModelIdentification& identification) {
  Scene out = scene;
  out.comparison.stiffness_scale.assign(scene.layers.size(), 1.0);
  for (std::size_t k = 0; k < identification.layers.size() && k < out.layers.size(); ++k) {
    const LayerIdentification& l = identification.layers[k];
    if (!l.identified) continue;
    out.comparison.stiffness_scale[k] = l.stiffness_scale;
    set_critical_force(out, k, l.critical_force_N);
  }
  return out;
}

}  // namespace puncture::validation
