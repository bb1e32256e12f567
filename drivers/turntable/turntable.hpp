// The rate/position turntable device interface: one bounded transaction set per call.
#pragma once

#include <optional>
#include <string>

#include "drivers/common/plausible.hpp"
#include "drivers/common/result.hpp"

namespace station::drivers {

/// Servo mode of the table.
enum class TurntableMode { off, position, rate };

/// "off", "position", "rate".
constexpr const char* to_string(TurntableMode m) {
  switch (m) {
    case TurntableMode::off:
      return "off";
    case TurntableMode::position:
      return "position";
    case TurntableMode::rate:
      return "rate";
  }
  return "unknown";
}

/// One reading of the table.
struct TurntableState {
  TurntableMode mode = TurntableMode::off;
  double angle_deg = 0;         ///< table angle, degrees in [0, 360)
  double rate_dps = 0;          ///< table rate, degrees per second
  bool in_position = false;     ///< position mode and settled on the demand
  bool at_rate = false;         ///< rate mode and at the demanded rate
  bool fault = false;           ///< drive fault
  bool interlock_open = false;  ///< safety interlock open (drive disabled)
  bool locked = false;          ///< axis lock engaged (read back from the lock register)
};

/// A demand to the table; unset optionals are left alone.
struct TurntableCommand {
  TurntableMode mode = TurntableMode::off;
  std::optional<double> position_deg{};  ///< position demand, degrees (position mode)
  std::optional<double> rate_dps{};      ///< rate demand, degrees per second (rate mode)
  std::optional<bool> lock{};            ///< engage (true) / release (false) the axis lock
};

/// A single-axis turntable.
class Turntable {
 public:
  virtual ~Turntable() = default;
  /// Opens the transport; blocks up to the timeout.
  virtual Result<void> connect() = 0;
  /// Reads mode, angle, rate and status; blocks up to a few response timeouts.
  virtual Result<TurntableState> read() = 0;
  /// Applies a demand; range-checks before writing anything.
  virtual Result<void> command(const TurntableCommand& c) = 0;
  /// Controlled stop (decelerate to rest, then off); blocks up to the timeout.
  virtual Result<void> stop() = 0;
  /// Device name for logs and records.
  virtual std::string name() const = 0;
  /// The rates this dialect can report, deg/s (docs/DEVICES.md, "Plausible readings"); by
  /// default any finite one. No I/O.
  virtual PlausibleRange rate_range_dps() const { return {}; }
  /// The angles a table reports, degrees (docs/DEVICES.md, "Plausible readings"): one turn
  /// either way (the interface's [0, 360), a signed +-180 form, a value not yet wrapped). No I/O.
  virtual PlausibleRange angle_range_deg() const { return {-360.0, 360.0}; }
  /// What the controller says about itself (probe); the default knows nothing.
  virtual Result<std::string> identify() { return std::string{}; }
};

}  // namespace station::drivers
