// Chi-squared quantiles from the regularized incomplete gamma function (A&S 6.5, 26.4).
#include "compensation/chi_squared.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace station::compensation {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr int kMaxTerms = 100000;
// Quantile stopping tolerance: well below the 1e-10 promised, above the ~1e-15 noise of P.
constexpr double kRelTol = 1e-13;

// exp(-x + a ln x - ln Gamma(a)): the common prefactor of A&S 6.5.29 and 6.5.31.
double gamma_prefactor(double a, double x) {
  return std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// P(a, x) by its power series, A&S 6.5.29: gamma*(a, x) = e^-x sum x^n / Gamma(a + n + 1).
// Converges quickly for x < a + 1.
double gamma_p_series(double a, double x) {
  double ap = a;
  double term = 1.0 / a;
  double sum = term;
  for (int n = 0; n < kMaxTerms; ++n) {
    ap += 1.0;
    term *= x / ap;
    sum += term;
    if (std::fabs(term) < std::fabs(sum) * kEps) break;
  }
  return sum * gamma_prefactor(a, x);
}

// Q(a, x) = 1 - P(a, x) by the continued fraction A&S 6.5.31, evaluated with the modified
// Lentz method (Numerical Recipes 3rd ed. §6.2, §5.2). Converges quickly for x >= a + 1.
double gamma_q_fraction(double a, double x) {
  constexpr double kTiny = std::numeric_limits<double>::min() / kEps;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxTerms; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kEps) break;
  }
  return gamma_prefactor(a, x) * h;
}

// Lower bound for the p-quantile of chi-squared(dof): P(a, y) <= y^a / Gamma(a + 1) (the series
// A&S 6.5.29 times e^-y <= 1), so y = (p Gamma(a + 1))^(1/a) has P(a, y) <= p.
double small_p_lower_bound(double p, double dof) {
  const double a = 0.5 * dof;
  return 2.0 * std::exp((std::log(p) + std::lgamma(a + 1.0)) / a);
}

// Starting guess: Wilson-Hilferty (A&S 26.4.17) with the normal quantile from A&S 26.2.23
// (|error| < 4.5e-4, plenty for a Newton start).
double wilson_hilferty_guess(double p, double dof) {
  const double q = p < 0.5 ? p : 1.0 - p;
  const double t = std::sqrt(-2.0 * std::log(q));
  double z = t - (2.515517 + t * (0.802853 + t * 0.010328)) /
                     (1.0 + t * (1.432788 + t * (0.189269 + t * 0.001308)));
  if (p < 0.5) z = -z;
  const double h = 2.0 / (9.0 * dof);
  const double c = 1.0 - h + z * std::sqrt(h);
  return dof * c * c * c;
}

// Density of chi-squared(dof) at x > 0.
double chi_squared_pdf(double x, double dof) {
  const double a = 0.5 * dof;
  return std::exp((a - 1.0) * std::log(x) - 0.5 * x - a * std::log(2.0) - std::lgamma(a));
}

}  // namespace

double regularized_gamma_p(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) {
    throw std::domain_error("regularized_gamma_p: need a > 0 and x >= 0, got a=" +
                            std::to_string(a) + " x=" + std::to_string(x));
  }
  if (x == 0.0) return 0.0;
  if (std::isinf(x)) return 1.0;
  if (x < a + 1.0) return gamma_p_series(a, x);
  return 1.0 - gamma_q_fraction(a, x);
}

double chi_squared_quantile(double p, double dof) {
  if (!(dof > 0.0) || !(p >= 0.0 && p <= 1.0)) {
    throw std::domain_error("chi_squared_quantile: need dof > 0 and 0 <= p <= 1, got p=" +
                            std::to_string(p) + " dof=" + std::to_string(dof));
  }
  if (p == 0.0) return 0.0;
  if (p == 1.0) return std::numeric_limits<double>::infinity();
  // Safeguarded Newton on F(x) = P(dof/2, x/2) - p: [lo, hi] always brackets the root; a step
  // that leaves the bracket (or a vanishing density) falls back to bisection (geometric while
  // lo > 0, so tiny quantiles are reached in few steps).
  double lo = small_p_lower_bound(p, dof);
  double hi = std::numeric_limits<double>::infinity();
  double x = std::fmax(wilson_hilferty_guess(p, dof), lo);
  for (int iter = 0; iter < 400; ++iter) {
    const double f = regularized_gamma_p(0.5 * dof, 0.5 * x) - p;
    if (f == 0.0) return x;
    if (f < 0.0) {
      lo = std::fmax(lo, x);
    } else {
      hi = std::fmin(hi, x);
    }
    const double pdf = chi_squared_pdf(x, dof);
    double next = pdf > 0.0 ? x - f / pdf : std::numeric_limits<double>::quiet_NaN();
    if (!(next > lo && next < hi)) {
      next = std::isinf(hi) ? 2.0 * std::fmax(x, lo) : (lo > 0.0 ? std::sqrt(lo * hi) : 0.5 * hi);
    }
    const bool bracketed = !std::isinf(hi) && hi - lo <= kRelTol * hi;
    if (std::fabs(next - x) <= kRelTol * x || bracketed) return next;
    x = next;
  }
  return x;
}

}  // namespace station::compensation
