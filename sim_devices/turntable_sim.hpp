// Simulated single-axis turntable: trapezoidal position moves and rate mode, served on the
// turntable register map. Time advances only through step_to().
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

#include "drivers/modbus/register_map.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace station::sim {

/// Motion limits and tolerances.
struct TurntableSimConfig {
  double max_rate_dps = 20.0;  ///< velocity limit for position moves, deg/s
  /// Velocity limit in rate mode, deg/s: a larger demand is held at it (and never at rate). A
  /// scale-factor ladder runs to +-300 deg/s; a rate table's drive goes to ~1000.
  double max_rate_mode_dps = 1000.0;
  double max_accel_dps2 = 10.0;   ///< acceleration limit, deg/s^2
  double in_position_deg = 0.01;  ///< |error| below which the table is in position, deg
  double at_rate_dps = 0.01;      ///< |rate error| below which the table is at rate, deg/s
  double step_s = 0.01;           ///< fixed integration step, s
};

/// The table model; thread-safe.
class TurntableSim final : public ModbusDeviceModel {
 public:
  /// `map`: turntable_map::generic_plc() (possibly overridden). No I/O.
  explicit TurntableSim(drivers::modbus::RegisterMap map, TurntableSimConfig cfg = {});

  /// Integrates motion up to `sim_time_s` in fixed steps.
  void step_to(double sim_time_s);
  /// Table angle, degrees in [0, 360).
  double angle_deg() const;
  /// The table's unwrapped angle turned since construction, deg, right-handed about the table
  /// axis (up): the sum of the 10 ms integration steps, never wrapped.
  double cumulative_angle_deg() const;
  /// The unwrapped angle at `t_s` within the kept track (t_s from the last forget_track_before
  /// up to now; earlier: the track's first angle, later: now's), deg. Exact for the integration:
  /// its steps hold the acceleration constant, and the track keeps a point wherever it changes.
  double cumulative_angle_at_deg(double t_s) const;
  /// Drops the track before `t_s` (what the gyros have already been stepped through).
  void forget_track_before(double t_s);
  /// Table rate, deg/s.
  double rate_dps() const;
  /// Fault: the rate reading shows `dps` instead of the model's rate (a lying encoder or a
  /// corrupt reply); std::nullopt ends it.
  void set_rate_shown_dps(std::optional<double> dps);
  /// What a face shows as the rate reading: the injected value, else the model's, deg/s.
  double shown_rate_dps() const;
  /// Fault: interlock open (drive disabled: mode off, table coasts to rest at max decel).
  void set_interlock_open(bool open);
  /// Fault: drive fault bit (drive disabled like the interlock).
  void set_fault(bool fault);

  const drivers::modbus::RegisterMap& register_map() const override { return map_; }
  /// Mode demand not 0..2, lock or stop not 0/1, a non-finite demand: 03.
  std::uint8_t check_write(const RegisterWrite& write) const override;
  int register_count() const override;
  /// The model as every dialect face serves it: mode 0 off, 1 position, 2 rate.
  int mode() const;
  /// Changes the mode; refused (false) while the interlock is open or a fault is active.
  bool set_mode(int mode);
  double position_demand_deg() const;
  double rate_demand_dps() const;
  void set_position_demand_deg(double deg);
  void set_rate_demand_dps(double dps);
  bool interlock_open() const;
  bool fault() const;
  const TurntableSimConfig& config() const { return cfg_; }

  void publish(modbus_mapping_t& regs) override;
  void on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) override;

 private:
  void step_once(double dt);
  void track_step(double accel_dps2);
  double velocity_demand() const;
  unsigned status_locked() const;

  drivers::modbus::RegisterMap map_;
  TurntableSimConfig cfg_;
  mutable std::mutex mutex_;
  double t_s_ = 0, angle_deg_ = 0, rate_dps_ = 0, position_demand_deg_ = 0, rate_demand_dps_ = 0;
  std::optional<double> rate_shown_dps_;
  // The motion since the gyros' last step: points where the acceleration changed, each with the
  // constant acceleration that follows it (t_s, unwrapped angle, rate, acceleration).
  struct TrackPoint {
    double t_s, angle_deg, rate_dps, accel_dps2;
  };
  std::vector<TrackPoint> track_{{0.0, 0.0, 0.0, 0.0}};
  double cumulative_deg_ = 0;
  bool snapped_ = false;  // the last step snapped onto its target: its acceleration was not kept
  int mode_ = 0;          // 0 off, 1 position, 2 rate
  bool locked_ = false, interlock_open_ = false, fault_ = false, stopping_ = false;
};

}  // namespace station::sim
