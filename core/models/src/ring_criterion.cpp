// ring_criterion.cpp: ring-w breakthrough on any surface deflection; see ring_criterion.hpp.
#include "puncture/comparison/ring_criterion.hpp"

#include <cmath>
#include <stdexcept>

#include "puncture/hex_lattice.hpp"

namespace puncture::comparison {

RingBreakthroughCriterion::RingBreakthroughCriterion(const ForceMeshParams& params)
    : rings_w_(params.rings_w), spacing_m_(params.spacing_L_m), threshold_m_(params.deformed_threshold_m) {
  if (rings_w_ < 1 || !(spacing_m_ > 0.0) || !(threshold_m_ > 0.0))
    throw std::invalid_argument("RingBreakthroughCriterion: need w >= 1, L > 0 and a threshold > 0");
  const HexLattice lattice = make_hex_lattice(rings_w_);
  ring_size_.assign(static_cast<std::size_t>(rings_w_), 0);
  for (int i = 0; i < lattice.node_count(); ++i) {
    points_.push_back(lattice.planar_position(i, spacing_m_));
    ring_of_point_.push_back(lattice.ring[static_cast<std::size_t>(i)]);
    radius_.push_back(points_.back().norm());
    ++ring_size_[static_cast<std::size_t>(lattice.ring[static_cast<std::size_t>(i)] - 1)];
  }
}

std::vector<double> RingBreakthroughCriterion::ring_means_m(const std::vector<double>& deflection) const {
  if (deflection.size() != points_.size())
    throw std::invalid_argument("RingBreakthroughCriterion: " + std::to_string(deflection.size()) +
                                " deflections for " + std::to_string(points_.size()) + " sample points");
  std::vector<double> mean(static_cast<std::size_t>(rings_w_), 0.0);
  for (std::size_t i = 0; i < points_.size(); ++i) mean[static_cast<std::size_t>(ring_of_point_[i] - 1)] += deflection[i];
  for (std::size_t j = 0; j < mean.size(); ++j) mean[j] /= ring_size_[j];
  return mean;
}

int RingBreakthroughCriterion::deformed_rings(const std::vector<double>& deflection) const {
  const std::vector<double> mean = ring_means_m(deflection);
  int j = 0;
  while (j < rings_w_ && std::abs(mean[static_cast<std::size_t>(j)]) > threshold_m_) ++j;
  return j;
}

}  // namespace puncture::comparison
