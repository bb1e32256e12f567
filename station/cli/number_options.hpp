// CLI11 validators for numeric options: a number must be finite and within its bound, so `nan`,
// `inf`, `1e308` and `--latitude 200` are refused at the edge with the option's name.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace station {

/// Accepts a finite number in [lo, hi]; the error reads "VALUE is not within LO..HI UNIT".
CLI::Validator finite_within(double lo, double hi, const std::string& unit);
/// Accepts a finite number in (0, hi].
CLI::Validator finite_positive(double hi, const std::string& unit);
/// Accepts decimal digits only (an unsigned integer that fits 64 bits): `-1` is refused, not
/// wrapped to 18446744073709551615.
CLI::Validator unsigned_integer();

}  // namespace station
