// Chamber over Modbus (TCP or RTU) through a register map (preset, possibly overridden).
#pragma once

#include <string>

#include "drivers/chamber/chamber.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/register_map.hpp"

namespace station::drivers {

/// A Watlow-style chamber controller on Modbus. Constructor does no I/O.
class ModbusChamber final : public Chamber {
 public:
  /// `name` for logs; `map` must define every chamber_map point (checked here, throws
  /// std::invalid_argument otherwise); `response_timeout_s` bounds each transaction.
  ModbusChamber(std::string name, modbus::Endpoint endpoint, modbus::RegisterMap map,
                double response_timeout_s = 0.5);

  Result<void> connect() override;
  Result<ChamberState> read() override;
  /// Writes ramp, then setpoint, then run; setpoint outside the chamber's limit registers
  /// gives ErrorKind::range and nothing is written.
  Result<void> command(const ChamberCommand& c) override;
  std::string name() const override { return name_; }

  /// Sets the tap every Modbus exchange passes (nullptr: none).
  void set_tap(Tap* tap) { client_.set_tap(tap); }
  /// The underlying client (for diagnostics).
  modbus::ModbusClient& client() { return client_; }

 private:
  Result<double> get(const char* point);
  Result<void> check_setpoint(double setpoint_c);

  std::string name_;
  modbus::RegisterMap map_;
  modbus::ModbusClient client_;
};

}  // namespace station::drivers
