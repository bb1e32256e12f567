#include "compensation/noise_edf.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace station::compensation {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kJMax = 100;  // Greenhall & Riley: exact sums up to J = 100 terms

// Greenhall & Riley 2003, eq. (7): the generalized autocovariance kernel sw(t) of phase noise
// with exponent alpha (a polynomial or t^k ln|t| per alpha).
double sw(double t, int alpha) {
  const double a = std::abs(t);
  const auto tlog = [&](int k) { return t == 0 ? 0.0 : std::pow(t, k) * std::log(a); };
  switch (alpha) {
    case 2:
      return -a;
    case 1:
      return tlog(2);
    case 0:
      return a * a * a;
    case -1:
      return tlog(4);
    case -2:
      return std::pow(a, 5);
    case -3:
      return tlog(6);
    case -4:
      return std::pow(a, 7);
    default:
      throw std::invalid_argument("greenhall_edf: alpha outside +2..-4");
  }
}

// Eq. (8): the kernel after the averaging filter of factor F (F = infinity: the limit).
double sx(double t, double f, int alpha) {
  if (std::isinf(f)) return sw(t, alpha + 2);
  return f * f * (2 * sw(t, alpha) - sw(t - 1 / f, alpha) - sw(t + 1 / f, alpha));
}

// Eq. (9): after the d-th difference: sum_k (-1)^k C(2d, d+k) sx(t + k), k = -d..d.
double sz(double t, double f, int alpha, int d) {
  double binom = 1;  // C(2d, 0)
  double sum = 0;
  for (int j = 0; j <= 2 * d; ++j) {  // k = j - d
    const double sign = ((j - d) % 2 == 0) ? 1.0 : -1.0;
    sum += sign * binom * sx(t + (j - d), f, alpha);
    binom = binom * (2 * d - j) / (j + 1);
  }
  return sum;
}

// Eq. (10): the basic sum over J lags of an M-term estimator with stride 1/S.
double basic_sum(double j_terms, double m_terms, double s, double f, int alpha, int d) {
  const double z0 = sz(0, f, alpha, d);
  const double zj = sz(j_terms / s, f, alpha, d);
  double sum = z0 * z0 + (1 - j_terms / m_terms) * zj * zj;
  for (int j = 1; j < static_cast<int>(j_terms); ++j) {
    const double z = sz(j / s, f, alpha, d);
    sum += 2 * (1 - j / m_terms) * z * z;
  }
  return sum;
}

// Table 2 (unmodified variances, alpha <= 0 and +1): a0, a1 of 1/edf ~ (a0 - a1 / r) / r, for
// d = 1, 2, 3; NaN where the variance does not converge.
struct A01 {
  double a0, a1;
};
A01 table2(int alpha, int d) {
  static const A01 t[7][3] = {{{1.5, 0.5}, {35.0 / 18, 1.0}, {2.31, 1.5}},               // alpha +2
                              {{78.6, 25.2}, {790.0, 410.0}, {9950.0, 6520.0}},          // +1
                              {{2.0 / 3, 1.0 / 6}, {2.0 / 3, 1.0 / 3}, {7.0 / 9, 0.5}},  // 0
                              {{NAN, NAN}, {0.852, 0.375}, {0.997, 0.617}},              // -1
                              {{NAN, NAN}, {1.079, 0.368}, {1.033, 0.607}},              // -2
                              {{NAN, NAN}, {NAN, NAN}, {1.053, 0.553}},                  // -3
                              {{NAN, NAN}, {NAN, NAN}, {1.302, 0.535}}};                 // -4
  return t[2 - alpha][d - 1];
}

// Table 3 (alpha = +1): b0, b1 of the sz(0) ~ b0 + b1 ln m normalization, d = 1, 2, 3.
A01 table3(int d) {
  static const A01 t[3] = {{6.0, 4.0}, {15.23, 12.0}, {47.8, 40.0}};
  return t[d - 1];
}

}  // namespace

double greenhall_edf(int alpha, int d, double m, double n_phase, bool overlapping) {
  if (alpha + 2 * d <= 1 || alpha > 2)
    throw std::invalid_argument("greenhall_edf: the variance does not converge for this alpha");
  const double f = m;                      // unmodified variance: filter factor m
  const double s = overlapping ? m : 1.0;  // stride factor
  const double l = m / f + m * d;          // filter length in phase samples
  const double m_terms = 1 + std::floor(s * (n_phase - l) / m);
  if (m_terms < 1) return 1.0;
  const double j_terms = std::min(m_terms, (d + 1) * s);
  const double r = m_terms / s;
  double inv = NAN;
  if (alpha == 2) {         // case 4: a closed form
    double c4 = 1, c2 = 1;  // C(4d, 2d), C(2d, d)
    for (int k = 1; k <= 2 * d; ++k) c4 = c4 * (2 * d + k) / k;
    for (int k = 1; k <= d; ++k) c2 = c2 * (d + k) / k;
    inv = (c4 / (c2 * c2) - d / 2.0 / r) / m_terms;
  } else if (alpha == 1) {  // case 3
    if (j_terms <= kJMax) {
      const double z0 = sz(0, m, 1, d);
      inv = basic_sum(j_terms, m_terms, s, m, 1, d) / (z0 * z0 * m_terms);
    } else {
      const A01 b = table3(d);
      const double norm = (b.a0 + b.a1 * std::log(m)) * (b.a0 + b.a1 * std::log(m));
      if (r > d + 1) {
        const A01 a = table2(1, d);
        inv = (a.a0 - a.a1 / r) / (norm * r);
      } else {
        const double mp = kJMax / r;
        inv = basic_sum(kJMax, kJMax, mp, mp, 1, d) / (norm * kJMax);
      }
    }
  } else {  // case 2: alpha <= 0
    if (j_terms <= kJMax) {
      const double fp = m * (d + 1) <= kJMax ? m : kInf;
      const double z0 = sz(0, fp, alpha, d);
      inv = basic_sum(j_terms, m_terms, s, fp, alpha, d) / (z0 * z0 * m_terms);
    } else if (r > d + 1) {
      const A01 a = table2(alpha, d);
      inv = (a.a0 - a.a1 / r) / r;
    } else {
      const double z0 = sz(0, kInf, alpha, d);
      inv = basic_sum(kJMax, kJMax, kJMax / r, kInf, alpha, d) / (z0 * z0 * kJMax);
    }
  }
  if (!(inv > 0) || !std::isfinite(inv)) return 1.0;
  return std::max(1.0 / inv, 1.0);
}

}  // namespace station::compensation
