// gauss_legendre.hpp: the project's Gauss-Legendre rule on [-1, 1] (the SH
// fit's theta grid, sh_fit.hpp; the wavenumber panels of the layered
// half-space, comparison/layered_half_space.hpp).
//
// In:  n >= 1 points; which values.
// Out: nodes ascending in (-1, 1), weights summing to 2.
//   Computed:      Newton's method on P_n from the Tricomi initial guess.
//   Table16Digits: the 8-point rule as a table of 16 significant digits
//                  (n must be 8). The layered half-space has always used
//                  these; they differ from the computed ones in the last bit,
//                  which would show in the comparison models' output.
// Throws std::invalid_argument for n < 1, or n != 8 with the table.
#pragma once

#include <Eigen/Core>

namespace puncture {

enum class GaussLegendreValues { Computed, Table16Digits };

void gauss_legendre(int n, Eigen::VectorXd& nodes, Eigen::VectorXd& weights,
                    GaussLegendreValues values = GaussLegendreValues::Computed);

}  // namespace puncture
