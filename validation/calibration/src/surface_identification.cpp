// identify_force_mesh() and the pressing reference it fits
// (surface_identification.hpp).
#include "puncture/validation/surface_identification.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "puncture/contact_surface.hpp"
#include "puncture/force_mesh.hpp"
#include "puncture/validation/levenberg_marquardt.hpp"

namespace puncture::validation {

namespace {

double layer_top_depth_m(const Scene& scene, std::size_t k) {
  double top = 0.0;
  for (std::size_t j = 0; j < k; ++j) top += scene.layers[j].thickness_m;
  return top;
}

/// The FEM's tip force (total force without parts) on the insertion branch at depth_m.
double fem_tip_force_at(const InsertionCurve& curve, double depth_m) {
  const std::vector<double>& force = curve.has_parts() ? curve.tip_force_N : curve.force_N;
  double best = std::numeric_limits<double>::infinity(), value = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < curve.size(); ++i) {
    if (curve.phase[i] != CurvePhase::Insertion) continue;
    const double d = std::abs(curve.depth_m[i] - depth_m);
    if (d < best) best = d, value = force[i];
  }
  if (!(best <= 1e-7)) throw std::invalid_argument(curve.source + ": no insertion sample at the profile depth " +
                                                   std::to_string(depth_m * 1e3) + " mm");
  return value;
}

const PlaneSurface& flat_surface() {
  static const PlaneSurface plane(0.0);
  return plane;
}

struct ModelPressing {
  std::vector<double> force_N;
  std::vector<std::vector<double>> ring_deflection_m;  ///< [sample][ring - 1]
};

/// The quasi-static mesh through the samples' contact deflections; false if a step fails.
bool press(const ForceMeshParams& p, double thickness_m, double density, const SurfacePressingReference& ref,
           int compare_rings, ModelPressing& out) {
  MeshIntegrationSettings settings;
  settings.integrator = MeshIntegrator::QuasiStatic;
  try {
    ForceMesh mesh(flat_surface(), {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()}, p, thickness_m, density,
                   settings);
    out.force_N.assign(ref.size(), 0.0);
    // Rings beyond the mesh (a smaller w than the compared rings) have no deflection.
    out.ring_deflection_m.assign(ref.size(), std::vector<double>(std::max(p.rings_w, compare_rings), 0.0));
    for (std::size_t s = 0; s < ref.size(); ++s) {
      mesh.advance(ref.contact_deflection_m[s]);
      out.force_N[s] = mesh.contact_reaction_N();
      for (int j = 1; j <= p.rings_w; ++j) out.ring_deflection_m[s][j - 1] = mesh.ring_mean_deflection_m(j);
    }
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

/// FEM deflection at ring j's radius (j - 1) L, or NaN outside the profile's radii.
double fem_deflection_at_ring(const RadialProfile& profile, int ring, double spacing_m) {
  double uz = 0.0;
  if (ring < 2 || !interpolate_linear(profile.r_m, profile.uz_m, (ring - 1) * spacing_m, uz))
    return std::numeric_limits<double>::quiet_NaN();
  return -uz;
}

/// The FEM's deflection at every compared ring of every sample (NaN outside
/// the profile's radii), found once per fit, and the scales of the residuals.
struct RingTargets {
  std::vector<std::vector<double>> fem_m;  ///< [sample][ring - 1], rings 2..compare_rings (ring 1: NaN)
  double force_N = 0.0, deflection_m = 0.0;
  std::size_t forces = 0, deflections = 0;
};

RingTargets ring_targets(const SurfacePressingReference& ref, double spacing_m, int compare_rings) {
  RingTargets t;
  t.forces = ref.size();
  for (std::size_t i = 0; i < ref.size(); ++i) {
    t.force_N = std::max(t.force_N, std::abs(ref.force_N[i]));
    std::vector<double> row(compare_rings, std::numeric_limits<double>::quiet_NaN());
    for (int j = 2; j <= compare_rings; ++j) {
      row[j - 1] = fem_deflection_at_ring(ref.profiles[i], j, spacing_m);
      if (std::isnan(row[j - 1])) continue;
      t.deflection_m = std::max(t.deflection_m, std::abs(row[j - 1]));
      ++t.deflections;
    }
    t.fem_m.push_back(std::move(row));
  }
  return t;
}

ForceMeshParams params_from(const ForceMeshParams& base, const std::vector<double>& x) {
  ForceMeshParams p = base;
  p.virtual_stiffness_N_per_m = std::exp(x[0]);
  p.surface_stiffness_N_per_m = std::exp(x[1]);
  p.surface_axial_stiffness_N_per_m = std::exp(x[2]);
  p.virtual_stiffening_m = std::exp(x[3]);
  return p;
}

void residuals_of(const ModelPressing& m, const SurfacePressingReference& ref, const RingTargets& t,
                  const SurfaceIdentificationOptions& o, std::vector<double>& r) {
  r.clear();
  const double wf = std::sqrt(o.force_weight / static_cast<double>(t.forces));
  for (std::size_t i = 0; i < ref.size(); ++i) r.push_back(wf * (m.force_N[i] - ref.force_N[i]) / t.force_N);
  const double wd = t.deflections ? std::sqrt(o.deflection_weight / static_cast<double>(t.deflections)) : 0.0;
  for (std::size_t i = 0; i < ref.size(); ++i)
    for (std::size_t j = 0; j < t.fem_m[i].size(); ++j)
      if (!std::isnan(t.fem_m[i][j])) r.push_back(wd * (m.ring_deflection_m[i][j] - t.fem_m[i][j]) / t.deflection_m);
}

SurfaceFitQuality quality_of(const ModelPressing& m, const SurfacePressingReference& ref, const RingTargets& t) {
  SurfaceFitQuality q;
  double sf = 0.0, sd = 0.0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    sf += std::pow(m.force_N[i] - ref.force_N[i], 2);
    for (std::size_t j = 0; j < t.fem_m[i].size(); ++j)
      if (!std::isnan(t.fem_m[i][j])) sd += std::pow(m.ring_deflection_m[i][j] - t.fem_m[i][j], 2);
  }
  q.force_rmse_relative = std::sqrt(sf / static_cast<double>(t.forces)) / t.force_N;
  q.deflection_rmse_relative = t.deflections ? std::sqrt(sd / static_cast<double>(t.deflections)) / t.deflection_m : 0.0;
  return q;
}

}  // namespace

SurfacePressingReference surface_pressing_reference(const FemResultFiles& fem, const Scene& scene, std::size_t layer) {
  if (layer >= scene.layers.size()) throw std::invalid_argument("surface_pressing_reference: no layer " + std::to_string(layer));
  SurfacePressingReference ref;
  ref.layer = scene.layers[layer].name;
  const auto profiles = fem.profiles.find(ref.layer);
  if (profiles == fem.profiles.end()) return ref;
  const double top = layer_top_depth_m(scene, layer);
  const auto broke = fem.puncture_depth_m.find(ref.layer);
  const double puncture = broke != fem.puncture_depth_m.end() ? broke->second : std::numeric_limits<double>::infinity();
  for (const RadialProfile& p : profiles->second) {
    const double z0 = p.depth_m - top;
    if (!(z0 > 0.0) || p.depth_m >= puncture || p.r_m.size() < 2) continue;
    if (-p.uz_m.front() < kFollowFraction * z0) break;  // the crack runs ahead of the tip from here on
    ref.contact_deflection_m.push_back(z0);
    ref.force_N.push_back(fem_tip_force_at(fem.curve, p.depth_m));
    ref.profiles.push_back(p);
  }
  return ref;
}

namespace {

/// K, k_s, k_a, z_v of a mesh with start's w and L, compared over compare_rings rings.
SurfaceIdentificationResult fit_rings(const ForceMeshParams& start, double thickness_m, double density_kg_per_m3,
                                      const SurfacePressingReference& ref, const SurfaceIdentificationOptions& o,
                                      int compare_rings) {
  if (ref.size() < kMinPressingProfiles)
    throw std::invalid_argument("identify_force_mesh: layer " + ref.layer + ": fewer than " +
                                std::to_string(kMinPressingProfiles) + " pressing profiles in the reference");
  if (!(o.bound_factor > 1.0)) throw std::invalid_argument("identify_force_mesh: bound_factor must be > 1");
  SurfaceIdentificationResult result;
  result.layer = ref.layer;
  result.before = start;
  result.parameter_names = {"K", "k_s", "k_a", "z_v"};
  const RingTargets targets = ring_targets(ref, start.spacing_L_m, compare_rings);
  if (!(targets.force_N > 0.0) || !(targets.deflection_m > 0.0))
    throw std::invalid_argument("identify_force_mesh: layer " + ref.layer + ": the reference has no force or no deflection");

  const double ks0 = start.surface_stiffness_N_per_m > 0.0 ? start.surface_stiffness_N_per_m : start.virtual_stiffness_N_per_m;
  const std::vector<double> p0{start.virtual_stiffness_N_per_m, ks0,
                               start.surface_axial_stiffness_N_per_m > 0.0 ? start.surface_axial_stiffness_N_per_m : ks0,
                               start.virtual_stiffening_m > 0.0 ? start.virtual_stiffening_m : thickness_m};
  std::vector<double> x0, lower, upper;
  for (double v : p0) {
    x0.push_back(std::log(v));
    lower.push_back(std::log(v / o.bound_factor));
    upper.push_back(std::log(v * o.bound_factor));
  }
  const ResidualFunction residual = [&](const std::vector<double>& x, std::vector<double>& r) {
    const ForceMeshParams p = params_from(start, x);
    ModelPressing m;
    if (!press(p, thickness_m, density_kg_per_m3, ref, compare_rings, m)) return false;
    residuals_of(m, ref, targets, o, r);
    return true;
  };

  ModelPressing before;
  if (!press(start, thickness_m, density_kg_per_m3, ref, compare_rings, before))
    throw std::runtime_error("identify_force_mesh: layer " + ref.layer + ": the start mesh cannot be pressed");
  result.quality_before = quality_of(before, ref, targets);

  LevenbergMarquardtOptions lm;
  lm.max_iterations = 200;
  lm.max_evaluations = 4000;
  lm.threads = o.threads;
  const LevenbergMarquardtResult fit = levenberg_marquardt(residual, x0, lower, upper, lm);
  result.status = fit.status;
  result.after = params_from(start, fit.x);
  ModelPressing after;
  if (!press(result.after, thickness_m, density_kg_per_m3, ref, compare_rings, after))
    throw std::runtime_error("identify_force_mesh: layer " + ref.layer + ": the identified mesh cannot be pressed");
  result.quality_after = quality_of(after, ref, targets);
  result.cost = fit.cost;

  std::vector<double> r0;
  residual(fit.x, r0);
  const Eigen::MatrixXd J = fit.jacobian_at_x && fit.jacobian.size() > 0
                                ? fit.jacobian
                                : finite_difference_jacobian(residual, fit.x, r0, lower, upper, 1e-3, o.threads);
  result.statistics = jacobian_statistics(J, Eigen::Map<const Eigen::VectorXd>(r0.data(), static_cast<Eigen::Index>(r0.size())));
  for (std::size_t i = 0; i < fit.x.size(); ++i) {
    result.standard_error_ln.push_back(result.statistics.standard_error[static_cast<Eigen::Index>(i)]);
    result.at_bound.push_back(fit.x[i] <= lower[i] + 1e-6 || fit.x[i] >= upper[i] - 1e-6);
  }

  result.contact_deflection_m = ref.contact_deflection_m;
  result.fem_force_N = ref.force_N;
  result.model_force_N = after.force_N;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    std::vector<double> radius, fem, model;
    for (std::size_t j = 0; j < targets.fem_m[i].size(); ++j) {
      if (std::isnan(targets.fem_m[i][j])) continue;
      radius.push_back(static_cast<double>(j) * result.after.spacing_L_m);
      fem.push_back(targets.fem_m[i][j]);
      model.push_back(after.ring_deflection_m[i][j]);
    }
    result.ring_radius_m.push_back(radius);
    result.fem_deflection_m.push_back(fem);
    result.model_deflection_m.push_back(model);
  }
  return result;
}

}  // namespace

SurfaceIdentificationResult identify_force_mesh(const ForceMeshParams& start, double thickness_m, double density_kg_per_m3,
                                                const SurfacePressingReference& ref,
                                                const SurfaceIdentificationOptions& o) {
  if (o.rings_search_radius < 0) throw std::invalid_argument("identify_force_mesh: rings_search_radius must be >= 0");
  std::vector<int> candidates;
  for (int w = std::max(2, start.rings_w - o.rings_search_radius); w <= start.rings_w + o.rings_search_radius; ++w)
    if (w == start.rings_w || (w - 1) * start.spacing_L_m < o.max_extent_m) candidates.push_back(w);
  // Every candidate is compared over the rings of the largest: a mesh smaller
  // than the FEM's tent leaves its outer rings undeflected.
  const int compare_rings = candidates.back();
  SurfaceIdentificationResult best;
  std::vector<std::pair<int, double>> costs;
  for (int w : candidates) {
    ForceMeshParams p = start;
    p.rings_w = w;
    SurfaceIdentificationResult r = fit_rings(p, thickness_m, density_kg_per_m3, ref, o, compare_rings);
    costs.push_back({w, r.cost});
    if (costs.size() == 1 || r.cost < best.cost) best = std::move(r);
  }
  // w is identified only when the objective tells the candidates apart: if
  // they all fit within kRingsTolerance of the best, the extent of the FEM's
  // deformed surface lies inside every candidate mesh, and w stays at w0.
  constexpr double kRingsTolerance = 0.02;
  double worst = best.cost;
  for (const auto& c : costs) worst = std::max(worst, c.second);
  best.rings_identified = candidates.size() > 1 && worst > (1.0 + kRingsTolerance) * best.cost;
  if (candidates.size() > 1 && !best.rings_identified && best.after.rings_w != start.rings_w) {
    ForceMeshParams p = start;
    best = fit_rings(p, thickness_m, density_kg_per_m3, ref, o, compare_rings);
    best.rings_identified = false;
  }
  best.before = start;
  best.rings_costs = costs;
  return best;
}

namespace {

std::string number(double v, int digits = 4) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

std::string with_error(double value, double se_ln, bool at_bound) {
  std::string s = number(value);
  if (at_bound) return s + " (**at a bound**)";
  if (!std::isfinite(se_ln)) return s + " (not determined)";
  const double percent = 100.0 * se_ln;  // two digits, whole percent from 10 % on (150 %, not 1.5e+02 %)
  return s + " +- " + (percent >= 10.0 ? number(std::round(percent), 6) : number(percent, 2)) + " %" +
         (se_ln > 1.0 ? " (**not identifiable**)" : "");
}

}  // namespace

std::vector<SurfaceParameterStatus> surface_parameter_statuses(const SurfaceIdentificationResult& r) {
  static const char* const pointers[4] = {"/force_mesh/K_N_per_mm", "/force_mesh/surface_stiffness_N_per_mm",
                                          "/force_mesh/surface_axial_stiffness_N_per_mm",
                                          "/force_mesh/virtual_stiffening_mm"};
  std::vector<SurfaceParameterStatus> out;
  for (std::size_t i = 0; i < 4 && i < r.standard_error_ln.size() && i < r.at_bound.size(); ++i) {
    SurfaceParameterStatus st{pointers[i], "identified", "", r.standard_error_ln[i]};
    if (!std::isfinite(st.relative_standard_error)) st.relative_standard_error = std::numeric_limits<double>::quiet_NaN();
    if (r.at_bound[i]) {
      st.status = "at a bound", st.reason = "ended at a bound of the surface fit";
    } else if (!std::isfinite(r.standard_error_ln[i])) {
      st.status = "not identifiable", st.reason = "standard error not determined (the fit does not see it)";
    } else if (r.standard_error_ln[i] > 1.0) {
      st.status = "not identifiable", st.reason = "relative standard error above 100 %";
    }
    out.push_back(st);
  }
  if (r.rings_costs.size() > 1)
    out.push_back({"/force_mesh/w", r.rings_identified ? "identified" : "not identifiable",
                   r.rings_identified ? "" : "the candidates' objectives differ by < 2 %: kept at its start"});
  return out;
}

std::string surface_identification_markdown(const std::vector<SurfaceIdentificationResult>& results) {
  std::ostringstream s;
  s << "| layer | profiles | contact deflection (mm) | w (objective per w) | K (N/mm) | k_s (N/mm) | k_a (N/mm) | z_v (mm) | "
       "force RMSE / peak | deflection RMSE / largest | optimiser |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const SurfaceIdentificationResult& r : results) {
    const ForceMeshParams& a = r.after;
    const double values[4] = {a.virtual_stiffness_N_per_m * 1e-3, a.surface_stiffness_N_per_m * 1e-3,
                              a.surface_axial_stiffness_N_per_m * 1e-3, a.virtual_stiffening_m * 1e3};
    s << "| " << r.layer << " | " << r.contact_deflection_m.size() << " | "
      << number(r.contact_deflection_m.front() * 1e3, 3) << " - " << number(r.contact_deflection_m.back() * 1e3, 3) << " | "
      << a.rings_w;
    if (r.rings_costs.size() > 1) {
      s << (r.rings_identified ? " identified" : " kept: **not identifiable**, the objective changes by < 2 % over") << " (";
      for (std::size_t i = 0; i < r.rings_costs.size(); ++i)
        s << (i ? ", " : "") << r.rings_costs[i].first << ": " << number(r.rings_costs[i].second, 3);
      s << ")";
    }
    for (int i = 0; i < 4; ++i) s << " | " << with_error(values[i], r.standard_error_ln[i], r.at_bound[i]);
    s << " | " << number(r.quality_before.force_rmse_relative, 3) << " -> " << number(r.quality_after.force_rmse_relative, 3)
      << " | " << number(r.quality_before.deflection_rmse_relative, 3) << " -> "
      << number(r.quality_after.deflection_rmse_relative, 3) << " | " << r.status << " |\n";
  }
  return s.str();
}

std::string surface_identification_csv(const std::vector<SurfaceIdentificationResult>& results) {
  std::ostringstream s;
  s << "layer,sample,contact_deflection_mm,fem_force_N,model_force_N,r_mm,fem_deflection_mm,model_deflection_mm\n";
  s << std::setprecision(9);
  for (const SurfaceIdentificationResult& r : results)
    for (std::size_t i = 0; i < r.contact_deflection_m.size(); ++i)
      for (std::size_t j = 0; j < r.ring_radius_m[i].size(); ++j)
        s << r.layer << ',' << i << ',' << r.contact_deflection_m[i] * 1e3 << ',' << r.fem_force_N[i] << ','
          << r.model_force_N[i] << ',' << r.ring_radius_m[i][j] * 1e3 << ',' << r.fem_deflection_m[i][j] * 1e3 << ','
          << r.model_deflection_m[i][j] * 1e3 << '\n';
  return s.str();
}

}  // namespace puncture::validation
