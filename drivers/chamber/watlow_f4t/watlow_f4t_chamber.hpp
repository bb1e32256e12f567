// A Watlow F4T on Modbus TCP/RTU, Data Map 1 (dialect "watlow_f4t"): float CDAB in the
// controller's display unit (deg C or deg F, read at connect), the controller's own setpoint ramp
// (ramp action / scale / rate), run through a configured event output, alarm 1 as the deviation
// alarm. At connect the part number (16..30) is read: a cascade controller (other registers) is
// refused; with the profile option the loops' process-value kinds (16536+) are read, so the air
// and a configured product loop must be temperatures and a %RH loop makes this a humidity chamber,
// whose humidity event output is switched off when the station starts the chamber. A temperature that reads as no
// temperature while the other word order would is refused (float_word_order.hpp); the units
// register is the TCP port's (6730) or, on a serial link or behind a gateway, the serial port's
// (14080). Constructor does no I/O.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "drivers/chamber/chamber.hpp"
#include "drivers/chamber/scaled_temperature.hpp"
#include "drivers/chamber/watlow_f4t/f4t_part_number.hpp"
#include "drivers/chamber/watlow_inputs.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/readback.hpp"
#include "drivers/modbus/register_map.hpp"

namespace station::drivers {

class WatlowF4tChamber final : public Chamber {
 public:
  /// `map` is watlow_f4t::map() (possibly overridden).
  WatlowF4tChamber(std::string name, modbus::Endpoint endpoint, modbus::RegisterMap map,
                   double response_timeout_s, std::unique_ptr<modbus::ModbusWire> wire = nullptr,
                   WatlowInputs inputs = {});

  Result<void> connect() override { return client_.connect(); }
  Result<ChamberState> read() override;
  /// Ramp (action "setpoint" at a rate in deg/min, or action off for a step), then setpoint
  /// (checked against the loop's limits), then run (the event output).
  Result<void> command(const ChamberCommand& c) override;
  std::string name() const override { return name_; }
  Result<ChamberIdentity> identify() override;

  void set_tap(Tap* tap) { client_.set_tap(tap); }
  void set_readback_every(int reads) { readback_.set_every(reads); }
  modbus::ModbusClient& client() { return client_; }

 private:
  Result<TemperatureScale> scale();
  Result<double> value(const char* point);
  Result<double> temperature_c(const char* point, const TemperatureScale& s);
  Result<void> read_commands(const TemperatureScale& s);
  Result<void> check_controller();
  Result<void> humidity_off();
  std::string input_notes() const;
  std::string link_notes() const;
  Error units_error(Error e) const;

  std::string name_;
  modbus::RegisterMap map_;
  modbus::ModbusClient client_;
  std::optional<TemperatureScale> scale_;
  std::uint64_t scale_connects_ = 0;
  modbus::ReadbackSchedule readback_;
  ChamberMode mode_ = ChamberMode::off;
  double product_c_ = 0, ramp_c_per_min_ = 0;
  bool run_enabled_ = false;
  WatlowInputs inputs_;
  watlow_f4t::F4tPartNumber part_;  // read with the scale, once per connection
  bool humidity_chamber_ = false;   // the loop after the air loop reads %RH (profile option)
};

}  // namespace station::drivers
