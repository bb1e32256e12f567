// The thermal-chamber device interface: one bounded transaction per call, none blocks past its
// timeout. Real (ModbusChamber) and simulated chambers live behind it.
#pragma once

#include <optional>
#include <string>

#include "drivers/common/result.hpp"

namespace station::drivers {

/// What the chamber controller is doing.
enum class ChamberMode { off, constant, ramping, hold };

/// Alarm flags as the controller reports them.
struct AlarmBits {
  bool deviation = false;        ///< air temperature outside the deviation band
  bool sensor_break = false;     ///< air sensor open/failed (air_c is then NaN)
  bool door_open = false;        ///< door switch open
  bool high_limit_trip = false;  ///< independent over-temperature limit tripped
  /// True if any flag is set.
  bool any() const { return deviation || sensor_break || door_open || high_limit_trip; }
};

/// One reading of the chamber. A driver may read the command registers and the informational points
/// (setpoint ramp, run, mode, product) less often than every read (ModbusChamber's readback_every),
/// returning their last read-back values in between; air, alarms and setpoint are always fresh.
struct ChamberState {
  double air_c = 0;           ///< air temperature, °C (NaN on sensor break)
  double product_c = 0;       ///< product (second sensor) temperature, °C
  double setpoint_c = 0;      ///< target setpoint, °C
  double ramp_c_per_min = 0;  ///< setpoint ramp rate, °C/min, 0 = step
  ChamberMode mode = ChamberMode::off;
  AlarmBits alarms;
  bool run_enabled = false;  ///< controller output enabled
};

/// A change to the chamber; unset fields are left alone.
struct ChamberCommand {
  std::optional<double> setpoint_c{};      ///< new setpoint, °C (checked against the limits)
  std::optional<double> ramp_c_per_min{};  ///< new ramp rate, °C/min, >= 0, 0 = step
  std::optional<bool> run{};               ///< enable/disable the controller output
};

/// A thermal chamber. Every call is one bounded transaction; none blocks past its timeout.
class Chamber {
 public:
  virtual ~Chamber() = default;
  /// Opens the transport; blocks up to the timeout.
  virtual Result<void> connect() = 0;
  /// Reads temperatures, mode, alarms; blocks up to a few response timeouts.
  virtual Result<ChamberState> read() = 0;
  /// Applies a command; range-checks before writing anything.
  virtual Result<void> command(const ChamberCommand& c) = 0;
  /// Device name for logs and records.
  virtual std::string name() const = 0;
};

/// "off", "constant", "ramping", "hold".
constexpr const char* to_string(ChamberMode m) {
  switch (m) {
    case ChamberMode::off:
      return "off";
    case ChamberMode::constant:
      return "constant";
    case ChamberMode::ramping:
      return "ramping";
    case ChamberMode::hold:
      return "hold";
  }
  return "unknown";
}

}  // namespace station::drivers
