// The paper's figure of merit: the std of the bias before and after compensation (0.13 on the
// paper's gyro), with the rounding level below which there is nothing to compensate. Declared in
// fit.hpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "compensation/fit.hpp"
#include "compensation/limits.hpp"

namespace station::compensation {

double sample_std(std::span<const double> v) {
  if (v.size() < 2) return 0.0;
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt(ss / static_cast<double>(v.size() - 1));
}

Evaluation evaluate(std::span<const double> before_dph, std::span<const double> after_dph,
                    double removed_dph) {
  double magnitude_dph = std::abs(removed_dph);
  double max_abs_before = 0;
  for (auto v : {before_dph, after_dph}) {
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!std::isfinite(v[i]))
        throw DataError("evaluate: value " + std::to_string(i) + ": " + finite_problem(v[i]));
    }
  }
  if (!std::isfinite(removed_dph)) throw DataError("evaluate: " + finite_problem(removed_dph));
  for (double b : before_dph) max_abs_before = std::max(max_abs_before, std::abs(b));
  magnitude_dph += max_abs_before;
  Evaluation e;
  e.std_before_dph = sample_std(before_dph);
  e.std_after_dph = sample_std(after_dph);
  // Rounding level of the std. Each bias is a bin mean of m rates of magnitude M minus a
  // constant; its rounding error grows like sqrt(m) u M for random rounding (u = eps/2; Higham,
  // Accuracy and Stability of Numerical Algorithms, 2nd ed., sec. 4.2 and 3.1), about 12 eps M
  // for the station's 600-sample bins. 64 eps M covers that with a margin of five, and is still
  // 1.4e-14 M: the bin-to-bin scatter of any real gyro (bias instability of 1e-4 deg/h or more
  // on rates up to the Earth rate, a relative 1e-6 at least) is eight orders above it. A std
  // before at or below it is rounding noise, not a bias to compensate.
  constexpr double kRoundingFactor = 64.0;
  const double rounding_level_dph =
      kRoundingFactor * std::numeric_limits<double>::epsilon() * magnitude_dph;
  if (e.std_before_dph > rounding_level_dph) {
    e.std_ratio = e.std_after_dph / e.std_before_dph;
    e.improvement_pct = 100.0 * (1.0 - *e.std_ratio);
  }
  return e;
}

}  // namespace station::compensation
