// What data the compensation core accepts: physical bounds on rates and temperatures, and the
// typed error for data outside them. Pure: callers turn a DataError into their own message.
#pragma once

#include <stdexcept>
#include <string>

namespace station::compensation {

/// Data the maths refuses (not finite, outside a physical bound, too few points, ...). A
/// std::invalid_argument, so a caller that catches those also catches this.
class DataError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Largest |rate| accepted, deg/h. 1e7 deg/h = 2778 deg/s, above the input range of any
/// strapdown gyro (ring-laser gyros such as Honeywell's GG1320AN are specified to +-1074 deg/s =
/// 3.9e6 deg/h; navigation-grade FOGs to a few hundred deg/s), and about 7e5 times the Earth
/// rate a gyro at rest on the rig sees. A larger value is a unit or parsing mistake. The bound
/// also keeps every sum the maths forms finite: squares are at most 1e14, so even 1e12 samples
/// sum to 1e26, nowhere near the 1.8e308 where a double overflows.
inline constexpr double kMaxAbsRateDph = 1e7;
/// Lowest temperature accepted, deg C: absolute zero.
inline constexpr double kMinTempC = -273.15;
/// Highest temperature accepted, deg C: far above any climatic chamber (typically -70..+180 C)
/// or gyro; keeps dT^4 of the model below 3e12.
inline constexpr double kMaxTempC = 1000.0;
/// Largest |temperature difference| accepted (gradients, T - T_ref), deg C.
inline constexpr double kMaxAbsTempDiffC = kMaxTempC - kMinTempC;

/// A number for messages: "%g" (short for 1e+308, "nan" and "inf" as such).
std::string number_text(double v);

/// Empty when `rate_dph` is finite and within +-kMaxAbsRateDph; otherwise what is wrong.
std::string rate_problem(double rate_dph);
/// Empty when `temp_c` is finite and within [kMinTempC, kMaxTempC]; otherwise what is wrong.
std::string temp_problem(double temp_c);
/// Empty when `diff_c` is finite and within +-kMaxAbsTempDiffC; otherwise what is wrong.
std::string temp_diff_problem(double diff_c);
/// Empty when `v` is finite; otherwise what is wrong.
std::string finite_problem(double v);

}  // namespace station::compensation
