// A Watlow Series F4 on Modbus RTU/TCP (dialects "watlow_f4" and "watlow_f4t_map2"): int16 with
// the unit's decimal places, deg C or deg F read from the controller, run through a configured
// event output. The F4 has no constant-mode ramp: controller_ramp() is false and the station
// ramps by moving the setpoint. What each input measures (608/618) is read at connect: the air
// input must be a temperature, the product input (configured, WatlowInputs) too; on a humidity
// chamber the humidity event output is switched off when the station starts the chamber. Data Map 2
// serves fewer registers (no status, limits or input units): the driver uses what the map has.
// Constructor does no I/O.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/chamber/chamber.hpp"
#include "drivers/chamber/scaled_temperature.hpp"
#include "drivers/chamber/watlow_inputs.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/readback.hpp"
#include "drivers/modbus/register_map.hpp"

namespace station::drivers {

class WatlowF4Chamber final : public Chamber {
 public:
  /// `model` names the dialect in identify(); `map` is watlow_f4::map() (possibly overridden).
  WatlowF4Chamber(std::string name, std::string model, modbus::Endpoint endpoint,
                  modbus::RegisterMap map, double response_timeout_s,
                  std::unique_ptr<modbus::ModbusWire> wire = nullptr, WatlowInputs inputs = {});

  Result<void> connect() override { return client_.connect(); }
  Result<ChamberState> read() override;
  /// Setpoint (checked against 602/603, or the configured limits where the map has none) and run
  /// (the event output; on a humidity chamber the humidity event is switched off with it); a ramp
  /// is not the F4's to apply and is ignored (the station ramps: controller_ramp()).
  Result<void> command(const ChamberCommand& c) override;
  std::string name() const override { return name_; }
  Result<ChamberIdentity> identify() override;
  bool controller_ramp() const override { return false; }
  /// What a signed 16-bit register with the unit's decimals carries: -32767..32767 (x 10^-dec,
  /// in its unit); -32768 (0x8000) is the int16's out-of-range mark, never a value
  /// (docs/DEVICES.md, "Plausible readings"). Before the scale is read: one decimal, deg C.
  PlausibleRange air_range_c() const override;
  /// One count of the setpoint register (300) in deg C: 10^-decimals (606), x 5/9 in deg F.
  double setpoint_resolution_c() const override;

  void set_tap(Tap* tap) { client_.set_tap(tap); }
  void set_readback_every(int reads) { readback_.set_every(reads); }
  modbus::ModbusClient& client() { return client_; }

 private:
  Result<TemperatureScale> scale();
  Result<void> read_input_kinds();
  Result<double> temperature_c(const char* point, const TemperatureScale& s);
  Result<void> read_commands();
  Result<std::pair<double, double>> setpoint_limits_c(const TemperatureScale& s);
  Result<void> humidity_off();

  std::string name_, model_;
  modbus::RegisterMap map_;
  modbus::ModbusClient client_;
  WatlowInputs inputs_;
  bool humidity_chamber_ = false;  // input 2 measures %RH (608/618), read with the scale
  std::optional<TemperatureScale> scale_, product_scale_;  // read once per connection
  std::uint64_t scale_connects_ = 0;
  modbus::ReadbackSchedule readback_;
  ChamberMode mode_ = ChamberMode::off;
  double product_c_ = 0;
  bool run_enabled_ = false;
};

}  // namespace station::drivers
