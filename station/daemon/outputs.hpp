// The rig's outputs — tower lamps and gyro power relays — written in one place, only where a
// level changes. What they should show is decided by the safety layer (Safety::outputs while a
// run goes on, idle_outputs() between runs, safety.hpp); this only carries it out.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "drivers/gpio/gpio_bank.hpp"
#include "station/daemon/safety.hpp"

namespace station {

class RigOutputs {
 public:
  /// `bank` may be null (a rig without GPIO: nothing to write); relays of slots 1..`slots`.
  RigOutputs(drivers::gpio::GpioBank* bank, std::size_t slots) : bank_(bank), slots_(slots) {}
  /// Writes each configured line whose level differs from the last written; a line whose
  /// write failed is written again next call. Returns each failed line's message. The order is
  /// red, amber, green, then the relays (recorded sessions replay it).
  std::vector<std::string> write(const SafetyOutputs& o);
  /// The levels are no longer known (someone else drove them): the next write writes all.
  void forget() { written_.clear(); }

 private:
  drivers::gpio::GpioBank* bank_;
  std::size_t slots_;
  std::map<std::string, bool> written_;  ///< role -> level as last written
};

}  // namespace station
