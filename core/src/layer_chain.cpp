#include "puncture/layer_chain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "puncture/scene.hpp"
#include "puncture/stiffening.hpp"

namespace puncture {

double link_force_N(const ChainLink& link, double r) {
  double f = link.intercept_N + link.slope_N_per_m * r;
  if (link.stiffening) f += stiffening_force_N(*link.stiffening, r);
  return f;
}

double link_deflection_m(const ChainLink& link, double force_N) {
  const double excess = force_N - link.intercept_N;
  if (!(excess > 0.0)) return 0.0;
  const double linear = excess / link.slope_N_per_m;  // upper bound: g >= 0
  if (!link.stiffening) return linear;
  // Newton from the right on h(r) = a + b r + g(r) - F (convex, increasing):
  // the iterates decrease monotonically to the root.
  double r = linear;
  for (int it = 0; it < 100; ++it) {
    const double h = link_force_N(link, r) - force_N;
    const double dh = link.slope_N_per_m + stiffening_stiffness_N_per_m(*link.stiffening, r);
    const double next = std::max(0.0, r - h / dh);
    if (!std::isfinite(next)) throw std::runtime_error("layer chain: non-finite link deflection");
    if (std::abs(next - r) <= 1e-15 * std::max(r, 1e-9)) return next;
    r = next;
  }
  return r;
}

double solve_series_chain(const ChainLink* links, int n, double D, double* r) {
  if (n < 1 || n > kMaxChainLinks) throw std::invalid_argument("layer chain: 1 to 16 links");
  if (!std::isfinite(D) || !(D > 0.0)) throw std::invalid_argument("layer chain: total deflection must be > 0");
  double lo = std::numeric_limits<double>::infinity();
  for (int j = 0; j < n; ++j) {
    if (!(links[j].slope_N_per_m > 0.0) || !std::isfinite(links[j].slope_N_per_m) ||
        !std::isfinite(links[j].intercept_N))
      throw std::invalid_argument("layer chain: link slopes must be > 0 and intercepts finite");
    lo = std::min(lo, links[j].intercept_N);  // every r_j(lo) = 0 < D
  }
  auto total = [&](double F, double& derivative) {
    double s = 0.0;
    derivative = 0.0;
    for (int j = 0; j < n; ++j) {
      r[j] = link_deflection_m(links[j], F);
      s += r[j];
      if (r[j] > 0.0) {
        double k = links[j].slope_N_per_m;
        if (links[j].stiffening) k += stiffening_stiffness_N_per_m(*links[j].stiffening, r[j]);
        derivative += 1.0 / k;
      }
    }
    return s;
  };
  // Upper bracket: grow until the chain is deflected by at least D.
  double max_slope = 0.0;
  for (int j = 0; j < n; ++j) max_slope = std::max(max_slope, links[j].slope_N_per_m);
  double step = max_slope * D, hi = lo + step, dsum = 0.0;
  for (int it = 0; total(hi, dsum) < D; ++it) {
    if (it > 200) throw std::runtime_error("layer chain: no force found for the deflection");
    lo = hi;
    step *= 2.0;
    hi = lo + step;
  }
  const double tol = 1e-12 * D + 1e-18;
  double F = hi;
  for (int it = 0; it < 200; ++it) {
    const double s = total(F, dsum);
    const double residual = s - D;
    if (std::abs(residual) <= tol) return F;
    if (residual > 0.0) hi = F; else lo = F;
    double next = dsum > 0.0 ? F - residual / dsum : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (hi - lo <= 1e-15 * std::max(1.0, std::abs(hi))) {
      total(hi, dsum);
      return hi;
    }
    F = next;
  }
  throw std::runtime_error("layer chain: force iteration did not converge");
}

}  // namespace puncture
