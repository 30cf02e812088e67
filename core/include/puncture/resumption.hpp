// resumption.hpp: surface resumption after breakthrough (seed paper Eq. 8).
//
// When a layer's surface breaks, its force-mesh nodes stop following the
// needle and return to their shape-matching goals (shape_matching.hpp)
// gradually. With p_i^b the node positions at the moment of breakthrough,
// every step
//     eta <- max(0, eta - eta_r)                   (eta starts at 1)
//     g_i  = shape-matching goals of the current positions (Eq. 6-7,
//            recomputed every step: "A is updated in real time")
//     p_i <- g_i + eta (p_i^b - g_i)               (Eq. 8)
// so the distance to the goal shrinks linearly to zero and the node sits on
// its goal after ceil(1 / eta_r) steps. (For this motion the goals do not
// drift: p - p_cm = R q + eta r keeps the polar rotation R of A.)
//
// In: rest positions (3 x n, m), node masses (n, kg), eta_r in (0, 1]
// (Layer::resumption_rate, per haptic step). All storage is allocated at
// construction; start() and step() do not allocate.
#pragma once

#include <Eigen/Core>

namespace puncture {

class SurfaceResumption {
 public:
  /// Throws std::invalid_argument for eta_r outside (0, 1] or mismatched sizes.
  SurfaceResumption(const Eigen::Matrix3Xd& rest_positions, const Eigen::VectorXd& masses_kg,
                    double resumption_rate);

  /// The surface broke with the nodes at broken_positions (3 x n): eta = 1.
  void start(const Eigen::Matrix3Xd& broken_positions);
  /// One step of Eq. (8). No effect before start() or after eta reached 0.
  void step();

  bool active() const { return active_; }
  double recovery_factor() const { return eta_; }
  int steps_taken() const { return steps_; }
  const Eigen::Matrix3Xd& positions() const { return current_; }
  const Eigen::Matrix3Xd& goals() const { return goals_; }

 private:
  Eigen::Matrix3Xd rest_, broken_, current_, goals_;
  Eigen::VectorXd masses_;
  double rate_;
  double eta_ = 1.0;
  int steps_ = 0;
  bool active_ = false;
};

}  // namespace puncture
