// Readings no device could give (issue 34 point 2): the rig's reading screened once a tick
// against each dialect's range (drivers/common/plausible.hpp) narrowed by the configuration. A
// value outside is a fault, never a value: taken out of the reading (chamber air NaN, the
// turntable's reading dropped as unreadable), reported once per episode and once at its end.
// No I/O.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "drivers/common/plausible.hpp"
#include "station/config/config.hpp"
#include "station/daemon/rig.hpp"
#include "station/daemon/rig_reading.hpp"
#include "station/store/events.hpp"

namespace station {

/// The ranges this rig's readings must lie in.
struct PlausibleRanges {
  drivers::PlausibleRange air_c;        ///< chamber air and setpoint read-back, deg C
  drivers::PlausibleRange rate_dps;     ///< turntable rate, deg/s
  drivers::PlausibleRange angle_deg{};  ///< turntable angle, degrees
};

/// The dialects' own ranges (asked each tick: a driver learns its scale and limits at connect).
/// The configured limits do not narrow them: a value outside the limits but one the device can
/// report is a real reading out of limits (Safety's immediate hold), not an implausible one.
PlausibleRanges plausible_ranges(const Rig& rig);

/// One implausible reading: the device, which reading, its value and the bound it broke.
struct Implausible {
  std::string device, quantity;
  double value = 0, bound = 0;
};

/// Screens `r` in place: an implausible chamber air or setpoint read-back becomes NaN (no value:
/// the sample keeps it empty, the setpoint watch skips it), an implausible turntable rate drops
/// the table's reading with its interlock (an unreadable input: the safety layer's blind ticks),
/// an implausible angle becomes NaN (no position). Returns what it took out. A sensor break's NaN
/// is the chamber's own alarm, not judged here.
std::vector<Implausible> screen_reading(RigReading& r, const PlausibleRanges& ranges);

/// Episodes of implausible readings, one tick's findings at a time. Not thread-safe.
class PlausibilityWatch {
 public:
  /// An implausible_reading event for each quantity that turns implausible, and an
  /// implausible_reading_end for each open one read plausibly again (`chamber_read`,
  /// `table_read`: the device answered this tick; without an answer an episode goes on).
  std::vector<EventNote> observe(const std::vector<Implausible>& found, bool chamber_read,
                                 bool table_read);
  /// Whether the chamber's air is in an implausible episode now.
  bool air_implausible() const { return open_.count("chamber air_c") != 0; }

 private:
  struct Episode {
    Implausible first;
    long ticks = 0;
  };
  std::map<std::string, Episode> open_;
};

}  // namespace station
