// gauss_legendre.cpp: Gauss-Legendre rules on [-1, 1]; see gauss_legendre.hpp.
#include "puncture/sh/gauss_legendre.hpp"

#include <cmath>
#include <stdexcept>

namespace puncture {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

void gauss_legendre(int n, Eigen::VectorXd& nodes, Eigen::VectorXd& weights, GaussLegendreValues values) {
  if (n < 1) throw std::invalid_argument("gauss_legendre: need n >= 1");
  nodes.resize(n);
  weights.resize(n);
  if (values == GaussLegendreValues::Table16Digits) {
    if (n != 8) throw std::invalid_argument("gauss_legendre: the 16-digit table has n = 8 only");
    // Positive half, ascending.
    static const double xs[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
    static const double ws[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    for (int i = 0; i < 4; ++i) {
      nodes(i) = -xs[3 - i], weights(i) = ws[3 - i];
      nodes(4 + i) = xs[i], weights(4 + i) = ws[i];
    }
    return;
  }
  for (int i = 0; i < (n + 1) / 2; ++i) {
    // Newton on P_n from the Tricomi initial guess (node i counted from +1).
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int iter = 0; iter < 100; ++iter) {
      double p0 = 1.0, p1 = x;  // P_0, P_1
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      const double pn = (n == 1) ? x : p1, pn1 = (n == 1) ? 1.0 : p0;
      dp = n * (x * pn - pn1) / (x * x - 1.0);
      const double dx = pn / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    {  // final derivative at the converged node
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = (n == 1) ? 1.0 : n * (x * p1 - p0) / (x * x - 1.0);
    }
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    nodes(n - 1 - i) = x;
    nodes(i) = -x;
    weights(n - 1 - i) = w;
    weights(i) = w;
  }
  if (n % 2 == 1) nodes(n / 2) = 0.0;
}

}  // namespace puncture
