// Numbers beside their limits (number_text.hpp).
#include "station/common/number_text.hpp"

#include <fmt/format.h>

#include <cstdlib>

namespace station {

std::string as_written(double v) {
  return fmt::format("{}", v);
}

std::string beside_limit(double v, double limit, int digits) {
  // The shortest round-trip text has at most 17 significant digits (IEEE 754 binary64).
  for (int d = digits; d < 17; ++d) {
    const std::string t = fmt::format("{:.{}g}", v, d);
    const double read = std::strtod(t.c_str(), nullptr);
    if (read != limit && (read > limit) == (v > limit)) return t;
  }
  return as_written(v);
}

}  // namespace station
