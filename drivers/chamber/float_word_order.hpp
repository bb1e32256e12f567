// Whether a temperature read as an IEEE-754 float came in the wrong word order. A unit whose
// "Modbus Word Order" is set at its panel (TestEquity F4T manual p. 14: Low High by default, or
// High Low) sends the same two words either way round; read the wrong way round, a temperature's
// low word lands in the exponent, and 25.0 reads 2.4e-41. Decided from the value alone; no I/O.
#pragma once

#include <optional>
#include <string>

#include "drivers/modbus/register_map.hpp"

namespace station::drivers {

/// Whether `v`, in the controller's unit (deg C or deg F), can be a temperature, a setpoint or a
/// limit: finite, and 0 or 1e-6 <= |v| <= 1e5.
bool plausible_temperature(double v);

/// The same words as `value` (a float32 `point` decoded in `point.order`) decoded in the other
/// word order.
double in_other_word_order(const modbus::Point& point, double value);

/// One line when `value` is no plausible temperature but the same words in the other order are
/// ("loop1_pv (register 2820) reads 2.4e-41 low word first; high word first it reads 25.0: ..."),
/// naming the `word_order` to configure; nullopt when the value is plausible (or neither is:
/// then it is no word-order question).
std::optional<std::string> word_order_mismatch(const modbus::Point& point, double value);

}  // namespace station::drivers
