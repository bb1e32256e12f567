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
  /// A temperature/humidity chamber: input 2 (F4) / loop 2 (F4T) reads %RH ([TE101H] p. 61),
  /// humidity control on event output 2 ([TE] p. 51), left on at the panel.
  bool humidity = false;
  /// An F4T with cascade control: its part number says so, and it serves no Data Map 2 ([TE]
  /// p. 47): every Data Map 2 request is answered exception 02.
  bool cascade = false;
  /// The Modbus address set at the panel ([TE] F4T manual 746854 p. 14: "Modbus Address: [1]").
  int modbus_address = 1;
  /// F4T: the float word order set at the panel ([TE] 746854 p. 14: "Modbus Word Order: [Low
  /// High], High Low"): cdab = low word first, the default; abcd = High Low.
  drivers::modbus::WordOrder float_words = drivers::modbus::WordOrder::cdab;
};

/// The relative humidity a simulated humidity chamber reads, %RH.
inline constexpr double kSimHumidityRh = 45.0;

/// Base: a face serves `map` from `chamber`.
class WatlowFace : public ModbusDeviceModel {
 public:
  WatlowFace(ChamberSim& chamber, drivers::modbus::RegisterMap map, WatlowPanel panel)
      : chamber_(chamber), map_(std::move(map)), panel_(panel) {}
  const drivers::modbus::RegisterMap& register_map() const override { return map_; }
  int register_count() const override { return sim::register_count(map_); }
  /// Whether the humidity event output is on (a humidity chamber's humidity control).
  bool humidity_on() const { return humidity_on_; }

 protected:
  /// Publishes `point` if this face's map serves it (Data Map 2 serves a subset of the F4's).
  void put(modbus_mapping_t& regs, const char* point, double value) {
    if (const auto* p = map_.find(point)) put_point(regs, *p, value);
  }
  /// The humidity event output's state (set at the panel: on), where the map serves one.
  bool humidity_on_ = true;
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
