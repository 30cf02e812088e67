#include "puncture/resumption.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "puncture/shape_matching.hpp"

namespace puncture {

SurfaceResumption::SurfaceResumption(const Eigen::Matrix3Xd& rest_positions, const Eigen::VectorXd& masses_kg,
                                     double resumption_rate)
    : rest_(rest_positions),
      broken_(rest_positions),
      current_(rest_positions),
      goals_(rest_positions),
      masses_(masses_kg),
      rate_(resumption_rate) {
  if (!(resumption_rate > 0.0 && resumption_rate <= 1.0))
    throw std::invalid_argument("resumption_rate (eta_r) must be in (0, 1] (got " + std::to_string(resumption_rate) +
                                ")");
  if (masses_kg.size() != rest_positions.cols())
    throw std::invalid_argument("resumption: one mass per node is required");
}

void SurfaceResumption::start(const Eigen::Matrix3Xd& broken_positions) {
  if (broken_positions.cols() != rest_.cols())
    throw std::invalid_argument("resumption: broken positions must have one column per node");
  broken_ = broken_positions;
  current_ = broken_positions;
  eta_ = 1.0;
  steps_ = 0;
  active_ = true;
}

void SurfaceResumption::step() {
  if (!active_ || eta_ <= 0.0) return;
  ++steps_;
  // eta = 1 - k eta_r, computed from the step count so that rounding cannot
  // leave a residue of 1e-16 after ceil(1 / eta_r) steps.
  eta_ = 1.0 - steps_ * rate_;
  if (eta_ < 1e-12) eta_ = 0.0;
  shape_matching_goals(rest_, current_, masses_, goals_);
  current_ = goals_ + eta_ * (broken_ - goals_);
}

}  // namespace puncture
