// inclined_path_mesh.cpp: see inclined_path_mesh.hpp.
#include "puncture/meshing/inclined_path_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace puncture::meshing {

namespace {

constexpr double kHalfPi = 1.57079632679489661923;

double core_radius(const InclinedPath& p) { return p.core_radius_m > 0.0 ? p.core_radius_m : 4.0 * p.needle_radius_m; }

void check_path(const InclinedPath& p) {
  auto fail = [](const std::string& field, const std::string& rule, double value) {
    std::ostringstream msg;
    msg << "incline_needle_path: path." << field << " = " << value << ": " << rule;
    throw std::invalid_argument(msg.str());
  };
  if (!(p.angle_rad >= 0.0 && p.angle_rad < kHalfPi)) fail("angle_rad", "must lie in [0, pi/2)", p.angle_rad);
  if (!std::isfinite(p.azimuth_rad)) fail("azimuth_rad", "must be finite", p.azimuth_rad);
  if (!(p.end_depth_m > 0.0) || !std::isfinite(p.end_depth_m)) fail("end_depth_m", "must be positive", p.end_depth_m);
  if (!(p.needle_radius_m > 0.0) || !std::isfinite(p.needle_radius_m))
    fail("needle_radius_m", "must be positive", p.needle_radius_m);
  if (!(p.core_radius_m >= 0.0) || !std::isfinite(p.core_radius_m))
    fail("core_radius_m", "must be >= 0 (0: four needle radii)", p.core_radius_m);
  if (!(core_radius(p) >= p.needle_radius_m)) fail("core_radius_m", "must be at least the needle radius", core_radius(p));
  if (!(p.sample_radius_m > core_radius(p)) || !std::isfinite(p.sample_radius_m))
    fail("sample_radius_m", "must exceed the core radius " + std::to_string(core_radius(p)) + " m", p.sample_radius_m);
}

}  // namespace

InclinedPath inclined_path_of(const Scene& scene) {
  InclinedPath path;
  path.angle_rad = scene.insertion.angle_deg * (kHalfPi / 90.0);
  path.azimuth_rad = scene.insertion.azimuth_deg * (kHalfPi / 90.0);
  path.end_depth_m = std::min(scene.insertion.target_depth_m, scene.total_thickness_m());
  path.needle_radius_m = scene.needle.radius_m;
  path.sample_radius_m = 0.5 * scene.sample.diameter_m;
  return path;
}

Eigen::Vector3d path_direction(const InclinedPath& path) {
  const double s = std::sin(path.angle_rad);
  return Eigen::Vector3d(s * std::cos(path.azimuth_rad), s * std::sin(path.azimuth_rad), -std::cos(path.angle_rad));
}

double inclined_path_jacobian_bound(const InclinedPath& path) {
  const double k = 1.0 / std::cos(path.angle_rad) - 1.0;
  const double r_c = core_radius(path);
  return 1.0 - (path.end_depth_m * std::tan(path.angle_rad) + k * r_c) / (path.sample_radius_m - r_c);
}

void incline_needle_path(HexMesh& mesh, const InclinedPath& path) {
  check_path(path);
  const double bound = inclined_path_jacobian_bound(path);
  if (!(bound >= kMinInclinedPathJacobian)) {
    std::ostringstream msg;
    msg << "incline_needle_path: path.angle_rad = " << path.angle_rad << " (" << path.angle_rad * 90.0 / kHalfPi
        << " deg) to a depth of " << path.end_depth_m * 1e3 << " mm in a sample of radius "
        << path.sample_radius_m * 1e3 << " mm bends the mesh too far: the Jacobian's lower bound " << bound
        << " is below " << kMinInclinedPathJacobian
        << " (reduce the angle or the target depth, or widen the sample)";
    throw std::invalid_argument(msg.str());
  }
  if (path.angle_rad == 0.0) return;  // the map is the identity
  const double tan_a = std::tan(path.angle_rad), k = 1.0 / std::cos(path.angle_rad) - 1.0;
  const Eigen::Vector3d e(std::cos(path.azimuth_rad), std::sin(path.azimuth_rad), 0.0);
  const double r_c = core_radius(path), R = path.sample_radius_m;
  for (Eigen::Vector3d& p : mesh.vertices) {
    const double r = std::hypot(p.x(), p.y());
    if (r >= R * (1.0 - 1e-12)) continue;  // on the outer wall (to the rounding of hypot): stays
    const double w = r <= r_c ? 1.0 : (R - r) / (R - r_c);
    const double shift = tan_a * std::min(-p.z(), path.end_depth_m) + k * std::clamp(p.dot(e), -r_c, r_c);
    p += (w * shift) * e;
  }
}

}  // namespace puncture::meshing
