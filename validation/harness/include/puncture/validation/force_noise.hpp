// force_noise.hpp: the sensor noise of a force-depth curve, estimated from the
// curve itself.
//
// In:  a curve and the indices of the samples to use (e.g. its insertion
//      phase, depth non-decreasing).
// Out: sigma (N), a robust estimate of the standard deviation of the force's
//      noise: each interior sample's residual from the straight line through
//      its two neighbours (r_i = F_i - (w F_(i-1) + (1 - w) F_(i+1)), w from
//      the depths; w = 1/2 where the neighbours share a depth), divided by
//      sqrt(1 + w^2 + (1 - w)^2) so that white noise of deviation sigma gives
//      residuals of deviation sigma, then 1.4826 x the median absolute
//      deviation of these residuals. Drops and the curve's own curvature are
//      outliers to the median, so a smooth curve sampled finely gives ~0.
//      0 when there are fewer than kMinNoiseSamples samples (too few to tell
//      noise from shape); never NaN.
#pragma once

#include <cstddef>
#include <vector>

#include "puncture/validation/metrics.hpp"

namespace puncture::validation {

constexpr std::size_t kMinNoiseSamples = 12;

double force_noise_sigma_N(const InsertionCurve& curve, const std::vector<std::size_t>& samples);

}  // namespace puncture::validation
