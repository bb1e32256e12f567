// The thermal-chamber device interface, independent of any wire: what a chamber is (air, product,
// setpoint, ramp, run, alarms, limits). One bounded transaction set per call, none blocks past
// its timeout. Each dialect (drivers/chamber/<dialect>/, registered in drivers/registry/) and the
// simulated chambers live behind it.
#pragma once

#include <optional>
#include <string>

#include "drivers/common/plausible.hpp"
#include "drivers/common/result.hpp"

namespace station::drivers {

/// What the chamber controller is doing. `profile`: a profile (program) started at the panel
/// runs, not the station's setpoint; `manual`: the loop is in manual (open-loop) output.
enum class ChamberMode { off, constant, ramping, hold, profile, manual };

/// Alarm flags as the controller reports them.
struct AlarmBits {
  bool deviation = false;        ///< air temperature outside the deviation band
  bool sensor_break = false;     ///< air sensor open/failed (air_c is then NaN)
  bool door_open = false;        ///< door switch open
  bool high_limit_trip = false;  ///< independent over-temperature limit tripped
  bool other = false;  ///< another alarm the controller raises (e.g. an ESPEC P300 ALARM? code)
  /// True if any flag is set.
  bool any() const { return deviation || sensor_break || door_open || high_limit_trip || other; }
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

/// What a chamber says about itself at probe (identify()): model, units and scaling as read
/// from the controller, so a unit in deg F or with other decimals is read correctly or refused.
struct ChamberIdentity {
  std::string model;     ///< dialect name, e.g. "watlow_f4t"
  std::string identity;  ///< what the controller reports (part number, ROM, model code)
  std::string units;     ///< "C" or "F" as the controller displays temperatures
  int decimals = -1;     ///< decimal places of its integers (-1: floats / text)
  double setpoint_low_c = 0, setpoint_high_c = 0;  ///< the controller's setpoint limits, C
  std::string notes;  ///< anything the station adapts to (units converted, no product)
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
  /// Reads what the controller says about itself (probe); the default knows nothing.
  virtual Result<ChamberIdentity> identify() { return ChamberIdentity{}; }
  /// True when the controller ramps its setpoint itself at a commanded rate (a constant-mode
  /// ramp); false (Watlow F4, ESPEC P300) and the station ramps by moving the setpoint each tick
  /// (ProtocolRunner) and ignores ramp commands. No I/O.
  virtual bool controller_ramp() const { return true; }
  /// The air temperatures this dialect can report, deg C (docs/DEVICES.md, "Plausible
  /// readings"); by default what a chamber's air sensor can read (kSensorRangeC). No I/O.
  virtual PlausibleRange air_range_c() const { return kSensorRangeC; }
  /// The widest span any chamber air sensor reads, deg C: a platinum RTD's (IEC 60751: -200 ...
  /// 850 C); a thermocouple of a test chamber reads within it too. Beyond it no sensor answers.
  static constexpr PlausibleRange kSensorRangeC{-200.0, 850.0};
  /// The step of the setpoint register in deg C (one decimal: 0.1): a read-back within it of
  /// what was written is that value. No I/O.
  virtual double setpoint_resolution_c() const { return 0.1; }
};

/// "off", "constant", "ramping", "hold", "profile", "manual".
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
    case ChamberMode::profile:
      return "profile";
    case ChamberMode::manual:
      return "manual";
  }
  return "unknown";
}

}  // namespace station::drivers
