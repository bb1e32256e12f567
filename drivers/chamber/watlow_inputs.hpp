// What a Watlow chamber driver (F4, F4T, F4T in Data Map 2) takes from the configuration besides
// its map: which input carries the product temperature — an explicit choice, checked against
// the input's units at connect, so a humidity input is never read as a temperature — and the
// setpoint limits of a unit that serves none (an F4T in Data Map 2). docs/DEVICES.md.
#pragma once

#include <optional>

namespace station::drivers {

struct WatlowInputs {
  int product_input = 0;                    ///< F4 input / F4T loop of the product sensor; 0: none
  std::optional<double> setpoint_low_c{};   ///< where the unit serves no limits, °C
  std::optional<double> setpoint_high_c{};  ///< likewise
};

}  // namespace station::drivers
