#include "puncture/validation/force_noise.hpp"

#include <algorithm>
#include <cmath>

namespace puncture::validation {

namespace {
double median_of(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(mid), v.end());
  const double upper = v[mid];
  if (v.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<long>(mid)));
}
}  // namespace

double force_noise_sigma_N(const InsertionCurve& c, const std::vector<std::size_t>& s) {
  if (s.size() < kMinNoiseSamples) return 0.0;
  std::vector<double> residuals;
  residuals.reserve(s.size());
  for (std::size_t i = 1; i + 1 < s.size(); ++i) {
    const double d0 = c.depth_m[s[i - 1]], d1 = c.depth_m[s[i]], d2 = c.depth_m[s[i + 1]];
    const double span = d2 - d0;
    const double w = span > 0.0 ? (d2 - d1) / span : 0.5;  // weight of the previous sample
    const double r = c.force_N[s[i]] - (w * c.force_N[s[i - 1]] + (1.0 - w) * c.force_N[s[i + 1]]);
    if (std::isfinite(r)) residuals.push_back(r / std::sqrt(1.0 + w * w + (1.0 - w) * (1.0 - w)));
  }
  if (residuals.size() < kMinNoiseSamples - 2) return 0.0;
  const double centre = median_of(residuals);
  for (double& r : residuals) r = std::abs(r - centre);
  return 1.4826 * median_of(residuals);
}

}  // namespace puncture::validation
