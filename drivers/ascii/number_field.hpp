// The one reader of a decimal number in an ASCII reply field (ESPEC P300, ACUTROL3000 NR2/NRf):
// blanks and a trailing CR around it and a leading '+' allowed, anything else refused, and never
// NaN or infinity. Shared by the dialects' parsers and their simulator faces. No I/O.
#pragma once

#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>

namespace station::drivers::ascii {

/// The finite number filling `field`, or nullopt.
inline std::optional<double> number_field(std::string_view field) {
  while (!field.empty() && (field.front() == ' ')) field.remove_prefix(1);
  while (!field.empty() && (field.back() == ' ' || field.back() == '\r')) field.remove_suffix(1);
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
  if (field.empty() || ec != std::errc{} || end != field.data() + field.size() || !std::isfinite(v))
    return std::nullopt;
  return v;
}

}  // namespace station::drivers::ascii
