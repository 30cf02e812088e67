// The real-time model runs of the calibration: layer parameters, the SH
// surface cache, the reference's trajectory (calibration.hpp, model_runs.hpp).
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "calibration_parameters.hpp"
#include "model_runs.hpp"
#include "puncture/validation/calibration.hpp"

namespace puncture::validation {

std::vector<LayerParameters> layer_parameters(const Scene& scene) {
  std::vector<LayerParameters> out;
  for (const Layer& l : scene.layers) {
    LayerParameters p;
    p.layer = l.name;
    p.virtual_stiffness_N_per_m = l.force_mesh.virtual_stiffness_N_per_m;
    p.damping_N_s_per_m2 = l.damping_N_s_per_m2;
    p.rings_w = l.force_mesh.rings_w;
    p.spacing_L_m = l.force_mesh.spacing_L_m;
    p.surface_stiffness_N_per_m = l.force_mesh.surface_stiffness_N_per_m;
    p.deformed_threshold_m = l.force_mesh.deformed_threshold_m;
    const BreakthroughCriterion& b = l.force_law.breakthrough;
    p.breakthrough = b.kind == BreakthroughCriterion::Kind::Rings           ? "rings"
                     : b.kind == BreakthroughCriterion::Kind::CriticalForce ? "critical_force"
                                                                            : "critical_energy";
    p.critical_force_N = b.critical_force_N;
    p.critical_energy_J = b.critical_energy_J;
    p.cutting_force_N = l.force_law.cutting_force_N;
    p.friction_dynamic_N_per_m = l.force_law.friction.dynamic_N_per_m;
    p.friction_static_N_per_m = l.force_law.friction.static_N_per_m;
    p.stiffening_quadratic_N_per_m2 = l.force_law.stiffening.quadratic_N_per_m2;
    p.stiffening_cubic_N_per_m3 = l.force_law.stiffening.cubic_N_per_m3;
    p.stiffening_exponential_N_per_m = l.force_law.stiffening.exponential_stiffness_N_per_m;
    out.push_back(p);
  }
  return out;
}

// ---------------------------------------------------------------------------
// Surface cache

SurfaceCache::SurfaceCache(const Scene& scene) : diameter_m_(scene.sample.diameter_m), degree_(scene.realtime.sh_degree) {
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    thickness_m_.push_back(scene.layers[k].thickness_m);
    const LayerDisc disc = layer_disc(scene, k);
    surfaces_.push_back(LayerSurface::fit(disc.top_z_m, disc.bottom_z_m, disc.radius_m, degree_));
    const LayerSurface& s = surfaces_.back();
    fits_.push_back({scene.layers[k].name, s.degree(), s.fit_report(), s.top_face_max_error_m(),
                     s.top_face_rms_error_m(), s.whole_surface_rms_error_m()});
  }
}

bool SurfaceCache::matches(const Scene& scene) const {
  if (scene.layers.size() != thickness_m_.size() || scene.sample.diameter_m != diameter_m_ ||
      scene.realtime.sh_degree != degree_)
    return false;
  for (std::size_t k = 0; k < thickness_m_.size(); ++k)
    if (scene.layers[k].thickness_m != thickness_m_[k]) return false;
  return true;
}

RealtimeModel SurfaceCache::build(const Scene& scene) const {
  if (!matches(scene))
    throw std::invalid_argument("SurfaceCache::build: the scene's geometry or SH degree differs from the cached surfaces");
  RealtimeModel model;
  std::vector<std::unique_ptr<ContactSurface>> owned;
  for (const LayerSurface& s : surfaces_) {
    auto copy = std::make_unique<LayerSurface>(s);
    model.surfaces.push_back(copy.get());
    owned.push_back(std::move(copy));
  }
  model.fits = fits_;
  model.simulator = std::make_unique<PunctureSimulator>(scene, std::move(owned));
  return model;
}

InsertionCurve simulate_insertion_curve(const Scene& scene, const SurfaceCache* cache) {
  RealtimeModel model = cache ? cache->build(scene) : build_realtime_model(scene);
  return simulate_curve(model, scene, "realtime model (" + scene.name + ")");
}

// ---------------------------------------------------------------------------
// Parameters: what is tuned, in which space, within which bounds

namespace calibration_detail {

double reference_speed(const Scene& scene, const InsertionCurve& ref) {
  double v = 0.0;
  if (ref.metadata_number("speed_mm_per_s", v)) {
    if (!(v > 0.0)) throw std::invalid_argument(ref.source + ": metadata speed_mm_per_s must be > 0");
    return v * kMm;
  }
  return scene.insertion.speed_m_per_s;
}

namespace {

// ---------------------------------------------------------------------------
// The reference's trajectory and the model runs

struct ReferenceTrajectory {
  double deepest_m = 0.0;
  double dwell_s = 0.0;            ///< 0 without dwell rows or time
  bool has_withdrawal = false;
  double withdrawal_speed_m_per_s = 0.0;
};

ReferenceTrajectory reference_trajectory(const Scene& scene, const InsertionCurve& ref) {
  ReferenceTrajectory t;
  for (std::size_t i : insertion_phase(ref)) t.deepest_m = std::max(t.deepest_m, ref.depth_m[i]);
  const std::vector<std::size_t> dwell = dwell_phase(ref);
  if (ref.has_time && dwell.size() >= 2) t.dwell_s = ref.time_s[dwell.back()] - ref.time_s[dwell.front()];
  const std::vector<std::size_t> out = withdrawal_phase(ref);
  t.has_withdrawal = out.size() >= 2;
  if (t.has_withdrawal) {
    double v = 0.0;
    if (ref.metadata_number("withdrawal_speed_mm_per_s", v) && v > 0.0) {
      t.withdrawal_speed_m_per_s = v * kMm;
    } else if (ref.has_velocity) {
      std::vector<double> speeds;
      for (std::size_t i : out)
        if (ref.velocity_m_per_s[i] < 0.0) speeds.push_back(-ref.velocity_m_per_s[i]);
      if (!speeds.empty()) {
        std::nth_element(speeds.begin(), speeds.begin() + static_cast<long>(speeds.size() / 2), speeds.end());
        t.withdrawal_speed_m_per_s = speeds[speeds.size() / 2];
      }
    }
    if (!(t.withdrawal_speed_m_per_s > 0.0)) t.withdrawal_speed_m_per_s = scene.insertion.withdrawal_speed_m_per_s;
  }
  return t;
}

}  // namespace

Scene objective_scene(const Scene& current, const ReferenceCurve& reference, const CalibrationOptions& o,
                      bool with_dwell, double turn_depth_m) {
  const InsertionCurve& ref = reference.curve;
  const ReferenceTrajectory rt = reference_trajectory(current, ref);
  Scene s = current;
  // The model runs with every effect of the scene, the damping force d h v
  // included: what `puncture run` and the real-time app render is compared.
  // Against a quasi-static reference (the FEM) d is not identifiable apart
  // from the friction (both grow with the shaft length): d stays fixed and
  // the tuned friction carries the rest.
  s.realtime.integrator = o.integrator;
  s.effects.surface_output = false;
  s.insertion.speed_m_per_s = reference_speed(current, ref);
  s.insertion.target_depth_m = std::min({rt.deepest_m, turn_depth_m, 0.999 * s.total_thickness_m()});
  if (!(s.insertion.target_depth_m > -s.insertion.start_height_m))
    throw std::invalid_argument(ref.source + ": the reference's deepest sample lies above the scene's start height");
  s.insertion.dwell_s = with_dwell ? rt.dwell_s : 0.0;
  s.insertion.withdrawal_speed_m_per_s = rt.has_withdrawal ? rt.withdrawal_speed_m_per_s
                                                           : std::max(0.2, 20.0 * s.insertion.speed_m_per_s);
  if (o.objective_depth_step_m > 0.0)
    s.realtime.haptic_rate_Hz = std::max(s.realtime.haptic_rate_Hz, s.insertion.speed_m_per_s / o.objective_depth_step_m);
  return s;
}

}  // namespace calibration_detail

Scene calibration_run_scene(const Scene& scene, const ReferenceCurve& reference, const CalibrationOptions& options) {
  return calibration_detail::objective_scene(scene, reference, options, true);
}

}  // namespace puncture::validation
