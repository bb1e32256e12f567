// Physical bounds on the data the compensation core accepts.
#include "compensation/limits.hpp"

#include <cmath>
#include <cstdio>

namespace station::compensation {
std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string finite_problem(double v) {
  return std::isfinite(v) ? std::string() : number_text(v) + " is not a finite number";
}

std::string rate_problem(double rate_dph) {
  if (!std::isfinite(rate_dph)) return finite_problem(rate_dph);
  if (std::abs(rate_dph) <= kMaxAbsRateDph) return {};
  return "rate " + number_text(rate_dph) + " deg/h is beyond +-" + number_text(kMaxAbsRateDph) +
         " deg/h (above any gyro's input range)";
}

std::string temp_problem(double temp_c) {
  if (!std::isfinite(temp_c)) return finite_problem(temp_c);
  if (temp_c >= kMinTempC && temp_c <= kMaxTempC) return {};
  return "temperature " + number_text(temp_c) + " C is outside " + number_text(kMinTempC) + ".." +
         number_text(kMaxTempC) + " C";
}

std::string temp_diff_problem(double diff_c) {
  if (!std::isfinite(diff_c)) return finite_problem(diff_c);
  if (std::abs(diff_c) <= kMaxAbsTempDiffC) return {};
  return "temperature difference " + number_text(diff_c) + " C is beyond +-" +
         number_text(kMaxAbsTempDiffC) + " C";
}

}  // namespace station::compensation
