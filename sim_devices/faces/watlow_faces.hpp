// The chamber model served as the Watlow controllers serve their registers: F4 (and an F4T in
// F4-compatibility map), F4T Data Map 1, F4P. Written from the tables transcribed from the
// makers' documents (sim_devices/sources/watlow_sources.hpp); never from a driver's map or class.
#pragma once

#include <cstdint>
#include <string>

#include "drivers/modbus/register_map.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"
#include "sim_devices/sources/watlow_sources.hpp"

namespace station::sim {

/// How a simulated Watlow is set up at its panel.
struct WatlowPanel {
  int decimals = 1;         ///< F4/F4P register 606
  bool fahrenheit = false;  ///< F4/F4P 901 = 0, F4T units 30
  int run_event = 1;        ///< the event output the chamber builder wired to "run"
};

/// Base: a face serves `map` from `chamber`.
class WatlowFace : public ModbusDeviceModel {
 public:
  WatlowFace(ChamberSim& chamber, drivers::modbus::RegisterMap map, WatlowPanel panel)
      : chamber_(chamber), map_(std::move(map)), panel_(panel) {}
  const drivers::modbus::RegisterMap& register_map() const override { return map_; }
  int register_count() const override { return sim::register_count(map_); }

 protected:
  void put(modbus_mapping_t& regs, const char* point, double value) {
    put_point(regs, map_.at(point), value);
  }
  /// A temperature as the integer the controller shows (decimals, unit).
  double raw_temp(double c) const;
  double c_of_raw(double raw) const;
  /// A temperature in the controller's unit as a float (F4T), and back.
  double unit(double c) const;
  double c_of_unit(double v) const;

  ChamberSim& chamber_;
  drivers::modbus::RegisterMap map_;
  WatlowPanel panel_;
};

/// Watlow F4 map (sources::f4): status 200 0/1 constant, 2/3 profile; run on an event output.
class F4Face final : public WatlowFace {
 public:
  F4Face(ChamberSim& chamber, WatlowPanel panel, int unit_id = 1, const char* name = "watlow_f4");
  std::uint8_t check_write(const RegisterWrite& write) const override;
  void publish(modbus_mapping_t& regs) override;
  void on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) override;
};

/// Watlow F4T Data Map 1 (sources::f4t): floats CDAB, the controller's ramp, events 63/62.
class F4tFace final : public WatlowFace {
 public:
  F4tFace(ChamberSim& chamber, WatlowPanel panel, int unit_id = 1, bool rtu = false);
  std::uint8_t check_write(const RegisterWrite& write) const override;
  void publish(modbus_mapping_t& regs) override;
  void on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) override;

 private:
  int ramp_action_ = sources::f4t::kOff, ramp_scale_ = sources::f4t::kMinutes;
  double ramp_rate_ = 0;
};

/// Watlow F4P (sources::f4p): model 5280, auto/manual, ramp to set point 1100-1102.
class F4pFace final : public WatlowFace {
 public:
  F4pFace(ChamberSim& chamber, WatlowPanel panel, int unit_id = 1);
  std::uint8_t check_write(const RegisterWrite& write) const override;
  void publish(modbus_mapping_t& regs) override;
  void on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) override;

 private:
  int ramp_mode_ = 0, ramp_scale_ = 0;
  double ramp_rate_raw_ = 1000;  // 100.0 deg/min with one decimal (p. 6.8 default)
};

}  // namespace station::sim
