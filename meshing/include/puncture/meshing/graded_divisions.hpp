// graded_divisions.hpp: split a length into intervals whose sizes form a
// geometric series (used for the radial annuli and the element heights).
//
// In:  length (m, > 0), a target size of the first interval (m, > 0), the
//      ratio of neighbouring sizes (>= 1), a minimum number of intervals.
// Out: the interval sizes (m), first to last; they sum to `length` (to
//      round-off) and size[i+1] = ratio * size[i] exactly in exact arithmetic.
//      The count is the one whose exact first size is closest (in log scale)
//      to the target, and at least `min_count`.
#pragma once

#include <vector>

namespace puncture::meshing {

std::vector<double> graded_divisions(double length, double first_size_target, double ratio,
                                     int min_count = 1);

/// Sizes of `count` geometric intervals (ratio >= 1) that sum to `length`.
std::vector<double> geometric_intervals(double length, int count, double ratio);

}  // namespace puncture::meshing
