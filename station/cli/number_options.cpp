// Numeric option validators: strict parsing (std::from_chars), finite, bounded.
#include "station/cli/number_options.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <optional>

namespace station {
namespace {

std::optional<double> parse_number(const std::string& s) {
  double v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ptr != s.data() + s.size()) return std::nullopt;
  if (ec == std::errc::result_out_of_range) return HUGE_VAL;  // refused as not finite below
  if (ec != std::errc{}) return std::nullopt;
  return v;
}

CLI::Validator bounded(double lo, double hi, bool open_low, const std::string& unit) {
  const std::string suffix = unit.empty() ? "" : " " + unit;
  const std::string range = open_low ? fmt::format("({:g}, {:g}]{}", lo, hi, suffix)
                                     : fmt::format("{:g}..{:g}{}", lo, hi, suffix);
  return CLI::Validator(
      [=](std::string& s) -> std::string {
        const auto v = parse_number(s);
        if (!v) return fmt::format("'{}' is not a number", s);
        if (!std::isfinite(*v)) return fmt::format("'{}' is not a finite number", s);
        if (*v < lo || *v > hi || (open_low && *v == lo))
          return fmt::format("{} is not within {}", s, range);
        return {};
      },
      "NUMBER in " + range);
}

}  // namespace

CLI::Validator finite_within(double lo, double hi, const std::string& unit) {
  return bounded(lo, hi, false, unit);
}

CLI::Validator finite_positive(double hi, const std::string& unit) {
  return bounded(0.0, hi, true, unit);
}

CLI::Validator unsigned_integer() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        std::uint64_t v = 0;
        const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (s.empty() || ptr != s.data() + s.size() || ec != std::errc{})
          return fmt::format("'{}' is not an unsigned integer (0..18446744073709551615)", s);
        return {};
      },
      "UINT");
}

}  // namespace station
