// Turntable over Modbus TCP through the turntable register map.
#pragma once

#include <string>

#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/read_plan.hpp"
#include "drivers/modbus/readback.hpp"
#include "drivers/modbus/register_map.hpp"
#include "drivers/turntable/turntable.hpp"

namespace station::drivers {

/// Limits the driver enforces before writing a demand.
struct TurntableLimits {
  double max_rate_dps = 500.0;  ///< |rate demand| bound, deg/s
};

/// A servo turntable on Modbus TCP. Constructor does no I/O.
class ModbusTurntable final : public Turntable {
 public:
  /// `map` must define every turntable_map point (throws std::invalid_argument otherwise).
  /// `wire`: the link under the client (default: libmodbus to `endpoint`).
  ModbusTurntable(std::string name, modbus::Endpoint endpoint, modbus::RegisterMap map,
                  TurntableLimits limits = {}, double response_timeout_s = 0.5,
                  std::unique_ptr<modbus::ModbusWire> wire = nullptr);

  Result<void> connect() override;
  Result<TurntableState> read() override;
  /// Reads the lock register back every `reads` reads (and on the read after a write or a
  /// reconnect; modbus/readback.hpp); mode, angle, rate and status are read every time.
  void set_readback_every(int reads) { readback_.set_every(reads); }
  /// Writes lock, demands, then mode; out-of-range demands give ErrorKind::range, nothing written.
  Result<void> command(const TurntableCommand& c) override;
  Result<void> stop() override;
  std::string name() const override { return name_; }

  /// Sets the tap every Modbus exchange passes (nullptr: none).
  void set_tap(Tap* tap) { client_.set_tap(tap); }
  /// The underlying client (back-off clock, diagnostics).
  modbus::ModbusClient& client() { return client_; }

 private:
  Result<void> check(const TurntableCommand& c) const;

  std::string name_;
  modbus::RegisterMap map_;
  TurntableLimits limits_;
  modbus::ModbusClient client_;
  std::vector<modbus::Point> read_points_;  // mode, angle, rate, status
  std::vector<modbus::ReadBlock> read_plan_;
  modbus::ReadbackSchedule readback_;
  bool locked_ = false;  // the lock register read back last
};

}  // namespace station::drivers
