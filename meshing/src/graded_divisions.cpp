#include <puncture/meshing/graded_divisions.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace puncture::meshing {

std::vector<double> geometric_intervals(double length, int count, double ratio) {
  if (!(length > 0.0) || !std::isfinite(length))
    throw std::invalid_argument("geometric_intervals: length must be positive and finite, got " +
                                std::to_string(length));
  if (count < 1) throw std::invalid_argument("geometric_intervals: count must be >= 1");
  if (!(ratio >= 1.0) || !std::isfinite(ratio))
    throw std::invalid_argument("geometric_intervals: ratio must be >= 1, got " + std::to_string(ratio));
  // Sum of first * ratio^k, k = 0..count-1, equals length.
  double weight_sum = 0.0;
  double w = 1.0;
  std::vector<double> sizes(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    sizes[static_cast<std::size_t>(k)] = w;
    weight_sum += w;
    w *= ratio;
  }
  for (double& s : sizes) s *= length / weight_sum;
  return sizes;
}

std::vector<double> graded_divisions(double length, double first_size_target, double ratio,
                                     int min_count) {
  if (!(first_size_target > 0.0) || !std::isfinite(first_size_target))
    throw std::invalid_argument("graded_divisions: first_size_target must be positive, got " +
                                std::to_string(first_size_target));
  if (!(ratio >= 1.0) || !std::isfinite(ratio))
    throw std::invalid_argument("graded_divisions: ratio must be >= 1, got " + std::to_string(ratio));
  if (!(length > 0.0) || !std::isfinite(length))
    throw std::invalid_argument("graded_divisions: length must be positive and finite, got " +
                                std::to_string(length));
  // Continuous count n* with first * (ratio^n - 1) / (ratio - 1) = length.
  const double n_star = ratio > 1.0
                            ? std::log1p((ratio - 1.0) * length / first_size_target) / std::log(ratio)
                            : length / first_size_target;
  const int n_lo = std::max(1, static_cast<int>(std::floor(n_star)) - 1);
  const int n_hi = std::max(n_lo, static_cast<int>(std::ceil(n_star)) + 1);
  int best = n_lo;
  double best_misfit = HUGE_VAL;
  for (int n = n_lo; n <= n_hi; ++n) {
    const double first = geometric_intervals(length, n, ratio).front();
    const double misfit = std::abs(std::log(first / first_size_target));
    if (misfit < best_misfit) {
      best_misfit = misfit;
      best = n;
    }
  }
  return geometric_intervals(length, std::max(best, min_count), ratio);
}

}  // namespace puncture::meshing
