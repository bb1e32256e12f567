// A Watlow Series F4P on Modbus RTU (dialect "watlow_f4p"): int16 with the unit's decimals,
// deg C or deg F read from the controller, its own "ramp to set point" (1100-1102), auto mode as
// "run". It has one input (no product temperature: NaN) and no event outputs: run off is
// refused (the chamber's run must then be wired elsewhere). Identity: register 0 = 5280.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "drivers/chamber/chamber.hpp"
#include "drivers/chamber/scaled_temperature.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/readback.hpp"
#include "drivers/modbus/register_map.hpp"

namespace station::drivers {

class WatlowF4pChamber final : public Chamber {
 public:
  WatlowF4pChamber(std::string name, modbus::Endpoint endpoint, modbus::RegisterMap map,
                   double response_timeout_s, std::unique_ptr<modbus::ModbusWire> wire = nullptr);

  Result<void> connect() override { return client_.connect(); }
  Result<ChamberState> read() override;
  Result<void> command(const ChamberCommand& c) override;
  std::string name() const override { return name_; }
  Result<ChamberIdentity> identify() override;

  void set_tap(Tap* tap) { client_.set_tap(tap); }
  void set_readback_every(int reads) { readback_.set_every(reads); }
  modbus::ModbusClient& client() { return client_; }

 private:
  Result<TemperatureScale> scale();
  Result<double> raw(const char* point) { return client_.read(map_.at(point)); }
  Result<double> temperature_c(const char* point, const TemperatureScale& s);
  Result<void> write_ramp(double ramp_c_per_min, const TemperatureScale& s);

  std::string name_;
  modbus::RegisterMap map_;
  modbus::ModbusClient client_;
  std::optional<TemperatureScale> scale_;
  std::uint64_t scale_connects_ = 0;
  modbus::ReadbackSchedule readback_;
  double ramp_c_per_min_ = 0;
  bool auto_ = false;
};

}  // namespace station::drivers
