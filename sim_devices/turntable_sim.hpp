// Simulated single-axis turntable: trapezoidal position moves and rate mode, served on the
// turntable register map. Time advances only through step_to().
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>

#include "drivers/modbus/register_map.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace station::sim {

/// Motion limits and tolerances.
struct TurntableSimConfig {
  double max_rate_dps = 20.0;     ///< velocity limit for position moves, deg/s
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
  double velocity_demand() const;
  unsigned status_locked() const;

  drivers::modbus::RegisterMap map_;
  TurntableSimConfig cfg_;
  mutable std::mutex mutex_;
  double t_s_ = 0, angle_deg_ = 0, rate_dps_ = 0, position_demand_deg_ = 0, rate_demand_dps_ = 0;
  std::optional<double> rate_shown_dps_;
  int mode_ = 0;  // 0 off, 1 position, 2 rate
  bool locked_ = false, interlock_open_ = false, fault_ = false, stopping_ = false;
};

}  // namespace station::sim
