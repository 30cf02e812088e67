// real_sh.cpp: fully normalised recurrence for the real SH basis; see real_sh.hpp.
#include "puncture/sh/real_sh.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace puncture {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kSqrt2 = 1.41421356237309504880;
}  // namespace

Eigen::Vector3d unit_vector_from_angles(double theta, double phi) {
  const double s = std::sin(theta);
  return {s * std::cos(phi), s * std::sin(phi), std::cos(theta)};
}

RealSHBasis::RealSHBasis(int degree) : degree_(degree) {
  if (degree < 0) {
    throw std::invalid_argument("RealSHBasis: degree must be >= 0, got " + std::to_string(degree));
  }
  const int n = sh_count(degree);
  a_.assign(n, 0.0);
  b_.assign(n, 0.0);
  diag_.assign(degree + 1, 0.0);
  for (int m = 1; m <= degree; ++m) diag_[m] = std::sqrt((2.0 * m + 1.0) / (2.0 * m));
  for (int m = 0; m <= degree; ++m) {
    for (int l = m + 2; l <= degree; ++l) {
      const double l2 = double(l) * l, m2 = double(m) * m, lm1 = double(l - 1) * (l - 1);
      a_[sh_index(l, m)] = std::sqrt((4.0 * l2 - 1.0) / (l2 - m2));
      b_[sh_index(l, m)] = std::sqrt((lm1 - m2) / (4.0 * lm1 - 1.0));
    }
  }
}

template <bool kWithGradient>
void RealSHBasis::evaluate_impl(const Eigen::Vector3d& u_in, double* values,
                                double* gradient, int max_order) const {
  const double norm = u_in.norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) {
    throw std::invalid_argument("RealSHBasis::evaluate: direction must be finite and non-zero");
  }
  const Eigen::Vector3d u = u_in / norm;
  const double x = u.x(), y = u.y(), z = u.z();
  const int L = degree_;

  double q_mm = 1.0 / std::sqrt(4.0 * kPi);  // q_00
  double c = 1.0, s = 0.0;                   // Re, Im of (x + iy)^m
  double c_prev = 0.0, s_prev = 0.0;         // Re, Im of (x + iy)^(m-1)

  // Writes the value and (optionally) the tangential gradient of one term
  // F = q(z) * trig(x, y) with polynomial gradient (fx, fy, q'(z) * trig).
  auto store = [&](int k, double value, double fx, double fy, double fz) {
    values[k] = value;
    if constexpr (kWithGradient) {
      const double radial = x * fx + y * fy + z * fz;
      gradient[3 * k + 0] = fx - radial * x;
      gradient[3 * k + 1] = fy - radial * y;
      gradient[3 * k + 2] = fz - radial * z;
    }
  };

  const int m_end = std::min(L, max_order);
  for (int m = 0; m <= m_end; ++m) {
    if (m > 0) {
      q_mm *= diag_[m];
      c_prev = c;
      s_prev = s;
      c = x * c_prev - y * s_prev;
      s = x * s_prev + y * c_prev;
    }
    double q1 = 0.0, q2 = 0.0;    // q_{l-1}, q_{l-2}
    double dq1 = 0.0, dq2 = 0.0;  // their z derivatives
    for (int l = m; l <= L; ++l) {
      double q, dq;
      if (l == m) {
        q = q_mm;
        dq = 0.0;
      } else if (l == m + 1) {
        const double f = std::sqrt(2.0 * m + 3.0);
        q = f * z * q_mm;
        dq = f * q_mm;
      } else {
        const double a = a_[sh_index(l, m)], b = b_[sh_index(l, m)];
        q = a * (z * q1 - b * q2);
        dq = a * (q1 + z * dq1 - b * dq2);
      }
      if (m == 0) {
        store(sh_index(l, 0), q, 0.0, 0.0, dq);
      } else {
        const double sq = kSqrt2 * q, sdq = kSqrt2 * dq, mq = kSqrt2 * m * q;
        // d/dx (x+iy)^m = m (x+iy)^(m-1); d/dy = i m (x+iy)^(m-1)
        store(sh_index(l, m), sq * c, mq * c_prev, -mq * s_prev, sdq * c);
        store(sh_index(l, -m), sq * s, mq * s_prev, mq * c_prev, sdq * s);
      }
      q2 = q1;
      q1 = q;
      dq2 = dq1;
      dq1 = dq;
    }
  }
}

void RealSHBasis::evaluate(const Eigen::Vector3d& u, double* values) const {
  evaluate_impl<false>(u, values, nullptr, degree_);
}

void RealSHBasis::evaluate(const Eigen::Vector3d& u, double* values, int max_order) const {
  evaluate_impl<false>(u, values, nullptr, max_order);
}

void RealSHBasis::evaluate_with_gradient(const Eigen::Vector3d& u, double* values,
                                         double* tangential_gradient, int max_order) const {
  evaluate_impl<true>(u, values, tangential_gradient, max_order);
}

void RealSHBasis::evaluate_with_gradient(const Eigen::Vector3d& u, double* values,
                                         double* tangential_gradient) const {
  evaluate_impl<true>(u, values, tangential_gradient, degree_);
}

double real_sh(int l, int m, double theta, double phi) {
  if (l < 0 || m < -l || m > l) {
    throw std::invalid_argument("real_sh: need 0 <= l and -l <= m <= l");
  }
  const RealSHBasis basis(l);
  std::vector<double> v(basis.count());
  basis.evaluate(unit_vector_from_angles(theta, phi), v.data());
  return v[sh_index(l, m)];
}

}  // namespace puncture
