// contact_surface.hpp: what the needle and the force mesh need to know about a
// layer's undeformed surface. Implemented by the SH layer surface
// (sh/layer_surface.hpp) and, for tests, by a plane.
//
// Positions in m, in the scene frame (z up, skin surface at z = 0).
#pragma once

#include <Eigen/Core>

namespace puncture {

struct SurfacePoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< m
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< unit, pointing out of the tissue (up for a top surface)
};

class ContactSurface {
 public:
  virtual ~ContactSurface() = default;

  /// First crossing of the ray origin + s * direction (s >= 0, direction unit)
  /// with the layer's top surface. Returns false if the ray misses it.
  /// Must not allocate (called inside the haptic tick).
  virtual bool intersect_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                             double& s, SurfacePoint& hit) const = 0;

  /// The point of the top surface above/below p along the local normal
  /// (closest point for points near the surface). Used to place force-mesh
  /// nodes; not called in the tick.
  virtual SurfacePoint project(const Eigen::Vector3d& p) const = 0;
};

/// The plane z = height with normal +z: the exact top surface of a flat layer.
class PlaneSurface final : public ContactSurface {
 public:
  explicit PlaneSurface(double height_m) : height_m_(height_m) {}
  bool intersect_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double& s,
                     SurfacePoint& hit) const override {
    if (direction.z() == 0.0) return false;
    s = (height_m_ - origin.z()) / direction.z();
    if (!(s >= 0.0)) return false;
    hit.position = origin + s * direction;
    hit.normal = Eigen::Vector3d::UnitZ();
    return true;
  }
  SurfacePoint project(const Eigen::Vector3d& p) const override {
    return {Eigen::Vector3d(p.x(), p.y(), height_m_), Eigen::Vector3d::UnitZ()};
  }

 private:
  double height_m_;
};

}  // namespace puncture
