#include "puncture/resumption.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace puncture {

SurfaceResumption::SurfaceResumption(const Eigen::Matrix3Xd& rest_positions, double recovery_time_s)
    : rest_(rest_positions), broken_(rest_positions), current_(rest_positions), recovery_time_s_(recovery_time_s) {
  if (!(recovery_time_s > 0.0) || !std::isfinite(recovery_time_s))
    throw std::invalid_argument("resumption: recovery time must be > 0 s (got " + std::to_string(recovery_time_s) + ")");
  if (!rest_positions.allFinite()) throw std::invalid_argument("resumption: non-finite rest positions");
}

void SurfaceResumption::set_rest_positions(const Eigen::Matrix3Xd& rest_positions) {
  if (rest_positions.cols() != rest_.cols())
    throw std::invalid_argument("resumption: rest positions must keep one column per node");
  rest_ = rest_positions;
  current_ = rest_positions;
  broken_ = rest_positions;
  active_ = false;
  eta_ = 1.0;
}

void SurfaceResumption::move_goals(const Eigen::Matrix3Xd& rest_positions) {
  if (rest_positions.cols() != rest_.cols())
    throw std::invalid_argument("resumption: rest positions must keep one column per node");
  broken_ += rest_positions - rest_;
  rest_ = rest_positions;
  current_ = rest_ + eta_ * (broken_ - rest_);
}

void SurfaceResumption::start(const Eigen::Matrix3Xd& broken_positions, double time_s) {
  if (broken_positions.cols() != rest_.cols())
    throw std::invalid_argument("resumption: broken positions must have one column per node");
  broken_ = broken_positions;
  current_ = broken_positions;
  start_time_s_ = time_s;
  eta_ = 1.0;
  active_ = true;
}

void SurfaceResumption::step(double time_s) {
  if (!active_ || eta_ == 0.0) return;
  eta_ = std::clamp(1.0 - (time_s - start_time_s_) / recovery_time_s_, 0.0, 1.0);
  if (eta_ < 1e-12) eta_ = 0.0;
  // Eq. (8) with the rest shape as goal: p = g + eta (p^b - g).
  current_ = rest_ + eta_ * (broken_ - rest_);
}

}  // namespace puncture
