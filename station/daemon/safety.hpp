// The safety layer no protocol can override: chamber commands clamped to the station's limits;
// interlock, e-stop or a device reading out of limits puts the chamber in a safe hold and stops the
// turntable.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "drivers/chamber/chamber.hpp"
#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/daemon/rig_reading.hpp"
#include "station/store/events.hpp"

namespace station {

/// Which safety sources the rig has (each configured source must be readable).
struct SafetySources {
  bool table = false;           ///< turntable (its interlock input)
  bool gpio_interlock = false;  ///< GPIO interlock line
  bool gpio_estop = false;      ///< GPIO e-stop line
};

/// What every source reported this tick; unset = configured but not readable this tick.
struct SafetyInputs {
  std::optional<drivers::ChamberState> chamber;  ///< also its door and high-limit alarms
  std::optional<bool> table_interlock_open;
  std::optional<bool> table_drive_fault;  ///< the turntable's drive-fault bit
  std::optional<bool> door_closed;        ///< the GPIO interlock line (closed = safe)
  std::optional<bool> estop_pressed;      ///< the GPIO e-stop line
  std::optional<double> air_c;  ///< last finite air reading (where a hold keeps the chamber)
  /// The chamber's air read this tick was no reading (plausibility.hpp): kBlindTicks in a row
  /// hold, as an unreadable interlock does.
  bool air_implausible = false;
  /// Hold for a setpoint another master wrote ([chamber] on_foreign_setpoint = "hold").
  bool setpoint_foreign = false;
};

/// The safety inputs of one rig reading (`air_c`: the last finite air reading).
SafetyInputs safety_inputs(const RigReading& in, std::optional<double> air_c);

/// The outputs the safety state asks for (tower lamps, gyro power relays).
struct SafetyOutputs {
  bool red = false, amber = false, green = false;
  bool gyro_power = false;
  bool operator==(const SafetyOutputs&) const = default;
};

/// The outputs between runs (serve's idle rig): amber, red while `fault`; gyros unpowered.
SafetyOutputs idle_outputs(bool fault);

/// Why the rig holds: each input's own last known state (a source that cannot be read keeps its
/// own last reading, never another source's), so a hold clears once every cause read clear.
struct SafetyCauses {
  bool table_interlock_open = false;       ///< the turntable's interlock input
  bool table_drive_fault = false;          ///< the turntable's drive fault (drive disabled)
  bool door_open = false;                  ///< the GPIO door interlock line
  bool chamber_door_open = false;          ///< the chamber's own door alarm
  bool estop_pressed = false;              ///< the GPIO e-stop line
  bool chamber_high_limit = false;         ///< the chamber's high-limit (over-temperature) trip
  bool chamber_sensor_break = false;       ///< the chamber's air sensor broken: no air reading
  bool chamber_air_implausible = false;    ///< the air implausible for kBlindTicks: no reading
  bool setpoint_foreign = false;           ///< another master's setpoint, held for (config)
  bool inputs_unreadable = false;          ///< interlock / e-stop unreadable for kBlindTicks
  std::vector<std::string> out_of_limits;  ///< the chamber's readings outside the limits
  bool interlock_open() const {
    return table_interlock_open || door_open || chamber_door_open || inputs_unreadable;
  }
  bool estop() const { return estop_pressed || chamber_high_limit; }
  /// A device fault someone must repair (tower lamp red): a broken sensor, a faulted drive.
  bool device_fault() const {
    return chamber_sensor_break || chamber_air_implausible || table_drive_fault;
  }
  bool any() const {
    return interlock_open() || estop() || device_fault() || setpoint_foreign ||
           !out_of_limits.empty();
  }
  /// The active causes in words ("chamber high-limit trip; GPIO e-stop pressed"), or "none".
  std::string text() const;
  /// What each cause that is on reads once it clears ("interlock closed", "e-stop released").
  std::string cleared_text() const;
  bool operator==(const SafetyCauses&) const = default;
};

/// One event to store (source "safety").
using SafetyEvent = EventNote;

/// What to do this tick. The caller sends the commands, then reports with acknowledge().
struct SafetyDecision {
  bool holding = false;
  bool entered = false;  ///< the hold began now: drop every pending protocol command
  bool cleared = false;  ///< the hold ended now: re-enter the protocol step
  std::vector<SafetyEvent> events;
  std::optional<drivers::ChamberCommand> chamber;  ///< hold command to (re)send
  bool stop_table = false;                         ///< turntable stop to (re)send
  SafetyOutputs outputs;
  std::optional<double> hold_air_c;  ///< where the chamber was held (for the step's re-entry)
};

/// The safety state of one run: limits enforcement, last-known inputs, blind ticks, the safe hold
/// and its command retries, the outputs. No I/O: inputs in, a decision out (chrony's small
/// modules), so every rule is a unit test without a rig.
class Safety {
 public:
  /// Ticks in a row with a configured interlock / e-stop unreadable before it counts as open.
  static constexpr int kBlindTicks = 5;

  explicit Safety(const LimitsConfig& limits, SafetySources sources = {})
      : limits_(limits), sources_(sources) {}

  /// `cmd` with setpoint and ramp clamped to the limits; a note per clamp in `notes`.
  drivers::ChamberCommand clamp(drivers::ChamberCommand cmd, std::vector<std::string>& notes) const;

  /// A copy of `p` with every setpoint and ramp inside the limits; a note per change. With
  /// `controller_ramp` false (a chamber that cannot ramp by itself: Watlow F4, ESPEC P300) a
  /// step becomes a station ramp at the maximum rate, the rate a step is bounded to anyway.
  Protocol clamp_protocol(const Protocol& p, std::vector<std::string>& notes,
                          bool controller_ramp = true) const;

  /// What the chamber reported this tick that lies outside the limits, one phrase each (read-back
  /// setpoint outside the setpoint limits; air beyond them by more than the air margin). Empty
  /// when all is inside or nothing was read.
  std::vector<std::string> judge(const std::optional<drivers::ChamberState>& chamber) const;

  /// One tick: every source's report in, the hold state, commands, events and outputs out. A
  /// source that could not be read keeps its last known value; unreadable for kBlindTicks in a
  /// row it counts as open (fail safe); a hold clears only on positive readings. A broken air
  /// sensor is a sensor fault (its own event) that holds: the hold takes no setpoint from an air
  /// reading it cannot trust, and a ramp resumes from the air read once the sensor reads again.
  SafetyDecision decide(const SafetyInputs& in);
  /// Between ticks (a GPIO edge): may enter the hold, never clears it.
  SafetyDecision decide_between_ticks(std::optional<bool> door_closed,
                                      std::optional<bool> estop_pressed,
                                      std::optional<double> air_c);
  /// What the devices said to this tick's hold commands; a refused one is sent again next tick.
  void acknowledge(bool chamber_hold_ok, bool table_stop_ok);

  /// True while the rig must stay in safe hold.
  bool holding() const { return holding_; }
  /// What holds the rig now (as of the last decision).
  const SafetyCauses& causes() const { return causes_; }
  /// True while readings out of limits hold the rig (a fault: tower lamp red).
  bool limits_fault() const { return limits_fault_; }
  /// The command that holds the chamber where it is (setpoint = air, step), clamped.
  drivers::ChamberCommand hold_command(double air_c) const;
  /// The outputs for the current state while a run is on (green running, amber hold, red
  /// fault; gyro power on unless holding).
  SafetyOutputs outputs() const;

 private:
  /// Takes the new causes; a message when any cause changed.
  std::optional<std::string> update(SafetyCauses causes);
  bool blind(const SafetyInputs& in) const;
  /// The event of the chamber's air sensor breaking (`broken`) or reading again.
  static SafetyEvent sensor_event(bool broken);
  /// One event per chamber alarm that came on or went off since the last reading (a sensor
  /// break has its own, sensor_event).
  void alarm_events(const drivers::AlarmBits& now, std::vector<SafetyEvent>& events);
  /// Applies a state change (or none) to `d`, and the hold's commands.
  void finish(SafetyDecision& d, bool was_holding, const std::optional<std::string>& change,
              const std::optional<drivers::ChamberState>& chamber, std::optional<double> air_c);

  LimitsConfig limits_;
  SafetySources sources_;
  bool holding_ = false;
  SafetyCauses causes_;
  bool limits_fault_ = false;
  int blind_ticks_ = 0;
  int implausible_ticks_ = 0;    ///< ticks in a row the chamber's air was implausible
  drivers::AlarmBits alarms_{};  ///< the chamber's alarms as last read
  std::optional<double> hold_air_c_;
  bool hold_acknowledged_ = false, table_stopped_ = false;
};

}  // namespace station
