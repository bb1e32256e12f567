// Simulated thermal chamber: a lumped first-order thermal model served on the chamber register
// map (the same wire definition ModbusChamber uses). Time advances only through step_to().
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>

#include "drivers/modbus/register_map.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace station::sim {

/// Model parameters. Air follows the effective setpoint as a first-order lag (time constant
/// air_tau_s), its rate of change clamped by the heating/cooling capacity; the product follows
/// air as a first-order lag (product_tau_s). Lumped-capacitance model (Newton's law of cooling).
struct ChamberSimConfig {
  double initial_c = 25.0;           ///< air, product and setpoint at t = 0, °C
  double ambient_c = 25.0;           ///< where air drifts with the output disabled, °C
  bool initial_run = true;           ///< controller output enabled at t = 0
  double heat_rate_c_per_min = 3.0;  ///< maximum heating rate, °C/min
  double cool_rate_c_per_min = 2.0;  ///< maximum cooling rate, °C/min
  double air_tau_s = 120.0;          ///< air time constant, s
  double product_tau_s = 600.0;      ///< product time constant, s
  double deviation_band_c = 5.0;     ///< deviation alarm when |air - effective setpoint| exceeds
  double setpoint_low_c = -70.0;     ///< setpoint low limit register, °C
  double setpoint_high_c = 180.0;    ///< setpoint high limit register, °C
  double broken_sensor_c = 999.9;    ///< value the air register shows on sensor break, °C
  double step_s = 0.1;               ///< fixed integration step, s
};

/// The chamber model; thread-safe (server thread reads/writes registers, tests step time).
class ChamberSim final : public ModbusDeviceModel {
 public:
  /// `map`: a chamber_map preset (possibly overridden). No I/O.
  explicit ChamberSim(drivers::modbus::RegisterMap map, ChamberSimConfig cfg = {});

  /// Integrates the model up to `sim_time_s` in fixed steps (no-op if not later than now).
  void step_to(double sim_time_s);
  /// Current simulated time, s.
  double sim_time_s() const;
  /// Air temperature of the model, °C (true value, even on sensor break).
  double air_c() const;
  /// Product temperature, °C.
  double product_c() const;
  /// Setpoint the ramp has reached, °C.
  double effective_setpoint_c() const;

  /// Fault: air sensor broken (sensor-break alarm, air register shows broken_sensor_c).
  void set_air_sensor_failed(bool failed);
  /// Fault: the air reading shows `c` deg C instead of the model's air (a lying sensor or a
  /// corrupt reply: no alarm; an integer face saturates it, -32768 / 0x8000 at the bottom);
  /// std::nullopt ends it.
  void set_air_shown_c(std::optional<double> c);
  /// What a face shows as the air reading: the injected value, else the model's air, deg C.
  double shown_air_c() const;
  /// Fault: door switch open (alarm bit).
  void set_door_open(bool open);
  /// Fault: independent high-limit tripped (alarm bit; output disabled while set).
  void set_high_limit_trip(bool tripped);
  /// Holds the setpoint ramp where it is (status "hold").
  void set_hold(bool hold);
  /// Someone at the front panel (or another master) sets the setpoint, deg C; clamped to the
  /// controller's limits like a Modbus write.
  void set_setpoint_c(double setpoint_c);
  /// Target setpoint, deg C.
  double setpoint_c() const;
  /// Alarm bits as the alarm register shows them (chamber_map::AlarmBit). Injected alarms stay
  /// until cleared by their setter: the model never rewrites them.
  unsigned alarms() const;

  /// The model as every dialect face serves it (sim_devices/faces/): run state, ramp, status
  /// (0 off, 1 constant, 2 ramping, 3 hold), the sensor fault, the configuration.
  bool run() const;
  /// Enables/disables the output (a ramp restarts from the air temperature, as a Watlow's does).
  void set_run(bool run);
  double ramp_c_per_min() const;
  /// Setpoint ramp rate, C/min (0 = step); negative or non-finite values are ignored.
  void set_ramp_c_per_min(double ramp);
  int status() const;
  bool air_sensor_failed() const;
  const ChamberSimConfig& config() const { return cfg_; }

  const drivers::modbus::RegisterMap& register_map() const override { return map_; }
  /// Run enable not 0/1, a negative or non-finite ramp or a non-finite setpoint: 03.
  std::uint8_t check_write(const RegisterWrite& write) const override;
  int register_count() const override;
  void publish(modbus_mapping_t& regs) override;
  void on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) override;

 private:
  void step_once(double dt);
  void set_run_locked(bool run);
  int status_locked() const;
  unsigned alarms_locked() const;

  drivers::modbus::RegisterMap map_;
  ChamberSimConfig cfg_;
  mutable std::mutex mutex_;
  double t_s_ = 0, air_c_, product_c_, setpoint_c_, effective_sp_c_, ramp_c_per_min_ = 0;
  std::optional<double> air_shown_c_;
  bool run_, hold_ = false, sensor_failed_ = false, door_open_ = false, high_limit_ = false;
};

}  // namespace station::sim
