// Temperatures carried as a controller displays them: integers with the unit's decimal places,
// in deg C or deg F (Watlow F4 / F4P: decimals 606, units 901), or floats in deg C or deg F
// (Watlow F4T). One conversion, used by the drivers and the simulators alike. No I/O.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>

namespace station::drivers {

/// How one controller's temperatures are scaled on the wire.
struct TemperatureScale {
  int decimals = 1;         ///< implied decimal places of an integer (0..3); ignored for floats
  bool fahrenheit = false;  ///< values in deg F (converted here), else deg C

  /// Engineering value on the wire (after the implied decimals) to deg C.
  double to_c(double wire) const { return fahrenheit ? (wire - 32.0) * 5.0 / 9.0 : wire; }
  /// deg C to the engineering value on the wire.
  double from_c(double c) const { return fahrenheit ? c * 9.0 / 5.0 + 32.0 : c; }
  /// A temperature difference or rate (per minute, per hour) on the wire to deg C.
  double delta_to_c(double wire) const { return fahrenheit ? wire * 5.0 / 9.0 : wire; }
  double delta_from_c(double c) const { return fahrenheit ? c * 9.0 / 5.0 : c; }
  /// Raw signed 16-bit integer to its engineering value: raw x 10^-decimals (Watlow F4P
  /// manual p. 6.13: 0 -> "0", 1 -> "0.0", 2 -> "0.00", 3 -> "0.000").
  double from_raw(std::int16_t raw) const { return raw * std::pow(10.0, -decimals); }
  /// Engineering value to the raw integer; nullopt when it does not fit 16 bits signed.
  std::optional<std::int16_t> to_raw(double value) const {
    const double r = std::nearbyint(value * std::pow(10.0, decimals));
    if (!(r >= -32768 && r <= 32767)) return std::nullopt;
    return static_cast<std::int16_t>(r);
  }
  /// deg C straight to the raw integer / back.
  std::optional<std::int16_t> raw_from_c(double c) const { return to_raw(from_c(c)); }
  double c_from_raw(std::int16_t raw) const { return to_c(from_raw(raw)); }
};

}  // namespace station::drivers
