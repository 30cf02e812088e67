// resumption.hpp: surface resumption after breakthrough (seed paper Eq. 8).
//
// When a layer's surface breaks, its force-mesh nodes stop following the
// needle and return to their goals gradually. With p_i^b the node positions
// at the moment of breakthrough (time t_b) and T the recovery time (s):
//     eta(t) = max(0, 1 - (t - t_b) / T)           (eta starts at 1)
//     p_i(t) = g_i + eta(t) (p_i^b - g_i)          (Eq. 8)
// so the distance to the goal shrinks linearly in time and the node sits on
// its goal from t_b + T on, whatever the haptic rate: T is given in seconds
// (Layer::resumption_time_s), not as a drop per haptic step.
//
// Goal. g_i = p_i^0, the rest position. Eq. (6)-(7) (shape matching,
// Mueller et al. 2005) would take as goal the best rigid fit of the rest
// shape to the current nodes, which keeps their centre of mass: a surface
// pushed down by the needle would recover its shape but stay sunk by its
// mean deflection, and a one-node mesh would not move at all. The layer's
// surface is bonded to the tissue around it, so neither a translation nor a
// rotation is free: the goal is the rest shape where it was (Fig. 5 of the
// paper shows the surfaces back at the guideline). For a deformation
// symmetric about the needle axis Eq. (6)-(7) give R = I, so this differs
// from the rigid fit only by the sinking translation. shape_matching.hpp
// keeps Eq. (6)-(7) (shape_matching_goals) for comparison.
// With Effects::coupled_surfaces the drawn surface is the larger of this
// recovery and the surface of the layer below (coupled_surfaces.hpp): the
// broken surface returns towards the deformed layers it rests on.
//
// In: rest positions (3 x n, m), recovery time T > 0 (s). All storage is
// allocated at construction; start() and step() do not allocate.
#pragma once

#include <Eigen/Core>

namespace puncture {

class SurfaceResumption {
 public:
  /// Throws std::invalid_argument for T <= 0 or non-finite rest positions.
  SurfaceResumption(const Eigen::Matrix3Xd& rest_positions, double recovery_time_s);

  /// The surface broke at time_s with the nodes at broken_positions (3 x n): eta = 1.
  void start(const Eigen::Matrix3Xd& broken_positions, double time_s);
  /// Eq. (8) at time_s (>= the start time). No effect before start().
  void step(double time_s);
  /// The rest positions changed (the mesh was laid out elsewhere); stops any recovery.
  void set_rest_positions(const Eigen::Matrix3Xd& rest_positions);
  /// The goals moved during a recovery (the mesh's nodes projected onto the
  /// curved surface after a break, see simulator.hpp): each node's broken
  /// position moves with its goal, so the recovery goes on from the same
  /// deformation towards the new goals. No allocation.
  void move_goals(const Eigen::Matrix3Xd& rest_positions);

  bool active() const { return active_; }
  bool recovered() const { return active_ && eta_ == 0.0; }
  double recovery_factor() const { return eta_; }
  double recovery_time_s() const { return recovery_time_s_; }
  const Eigen::Matrix3Xd& positions() const { return current_; }
  const Eigen::Matrix3Xd& goals() const { return rest_; }

 private:
  Eigen::Matrix3Xd rest_, broken_, current_;
  double recovery_time_s_;
  double start_time_s_ = 0.0;
  double eta_ = 1.0;
  bool active_ = false;
};

}  // namespace puncture
