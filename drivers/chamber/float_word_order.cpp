// The word-order check of float temperatures (see the header).
#include "drivers/chamber/float_word_order.hpp"

#include <fmt/format.h>

#include <cmath>

#include "drivers/modbus/map_overrides.hpp"

namespace station::drivers {
namespace mb = modbus;

namespace {

// The smallest and largest magnitudes a temperature of a chamber controller takes in deg C or
// deg F (its limits are a few hundred degrees; F4T ranges end at 99,999: Watlow F4T manual
// p. 225); a denormal or 1e-20 is no reading.
constexpr double kSmallest = 1e-6, kLargest = 1e5;

mb::WordOrder other(mb::WordOrder o) {
  return o == mb::WordOrder::abcd ? mb::WordOrder::cdab : mb::WordOrder::abcd;
}

const char* words_text(mb::WordOrder o) {
  return o == mb::WordOrder::cdab ? "low word first" : "high word first";
}

}  // namespace

bool plausible_temperature(double v) {
  const double a = std::fabs(v);
  return std::isfinite(v) && (a == 0 || (a >= kSmallest && a <= kLargest));
}

double in_other_word_order(const mb::Point& point, double value) {
  // `value` came from one float: its words again, in the order they were read.
  const auto words = mb::float_to_words(static_cast<float>(value / point.scale), point.order);
  return static_cast<double>(mb::words_to_float(words.data(), other(point.order))) * point.scale;
}

std::optional<std::string> word_order_mismatch(const mb::Point& point, double value) {
  if (point.type != mb::PointType::float32 || plausible_temperature(value)) return std::nullopt;
  const double swapped = in_other_word_order(point, value);
  if (!plausible_temperature(swapped)) return std::nullopt;
  return fmt::format(
      "{} (register {}) reads {:.3g} {}; {} it reads {:.2f}: the unit's Modbus Word Order is "
      "the other one (set word_order = \"{}\")",
      point.name, point.address, value, words_text(point.order), words_text(other(point.order)),
      swapped, mb::float_word_order_name(other(point.order)));
}

}  // namespace station::drivers
