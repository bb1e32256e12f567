// Chamber over Modbus (TCP or RTU) through a register map (preset, possibly overridden).
#pragma once

#include <string>
#include <vector>

#include "drivers/chamber/chamber.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/read_plan.hpp"
#include "drivers/modbus/readback.hpp"
#include "drivers/modbus/register_map.hpp"

namespace station::drivers {

/// A Watlow-style chamber controller on Modbus. Constructor does no I/O.
class ModbusChamber final : public Chamber {
 public:
  /// Default largest run of unused registers read() fetches to merge two points into one read:
  /// none. A strict controller (the Watlow F4 among them) answers a block that covers an
  /// unimplemented register with exception 02, so only adjacent points share a read.
  static constexpr int kDefaultMaxReadGap = 0;

  /// `name` for logs; `map` must define every chamber_map point (checked here, throws
  /// std::invalid_argument otherwise); `response_timeout_s` bounds each transaction.
  /// `wire`: the link under the client (default: libmodbus to `endpoint`; replay passes a
  /// recorded one).
  ModbusChamber(std::string name, modbus::Endpoint endpoint, modbus::RegisterMap map,
                double response_timeout_s = 0.5,
                std::unique_ptr<modbus::ModbusWire> wire = nullptr);

  Result<void> connect() override;
  /// One block read per group of nearby points (same unit and function code, see
  /// set_max_read_gap); the first failing transaction's error is returned.
  Result<ChamberState> read() override;
  /// Writes ramp, then setpoint, then run; setpoint outside the chamber's limit registers
  /// gives ErrorKind::range and nothing is written.
  Result<void> command(const ChamberCommand& c) override;
  std::string name() const override { return name_; }
  /// The map's name and its setpoint limits (the generic map has no identity register).
  Result<ChamberIdentity> identify() override;

  /// Sets the tap every Modbus exchange passes (nullptr: none).
  void set_tap(Tap* tap) { client_.set_tap(tap); }
  /// Largest run of unused registers read() may fetch to merge two points (default 0 = only
  /// adjacent points; -1 = one transaction per point; > 0 only for a controller known to serve
  /// reads of unimplemented registers).
  void set_max_read_gap(int registers);
  /// Block reads a read() with the command registers performs (for diagnostics and tests).
  const std::vector<modbus::ReadBlock>& read_plan() const { return read_plan_; }
  /// Reads back ramp and run (and the informational status and product temperature) every
  /// `reads` reads, and on the read after a write or a reconnect (modbus/readback.hpp); the
  /// reads between return the values read back last. Alarms, air and the setpoint (judged by
  /// the safety layer every tick) are read every time. 1: everything on every read.
  void set_readback_every(int reads) { readback_.set_every(reads); }
  /// The underlying client (for diagnostics).
  modbus::ModbusClient& client() { return client_; }

 private:
  Result<std::vector<double>> read_values();
  Result<void> check_setpoint(double setpoint_c);
  /// The setpoint limits, low and high: two reads, on the wire together with a pipeline.
  Result<std::vector<double>> limits();

  std::string name_;
  modbus::RegisterMap map_;
  modbus::ModbusClient client_;
  std::vector<modbus::Point> read_points_;  // in the order of the state fields (see .cpp)
  std::vector<modbus::ReadBlock> read_plan_;
  std::vector<modbus::ReadBlock> live_plan_;   // alarms, air, setpoint
  std::vector<modbus::Point> limit_points_;    // setpoint low, high
  std::vector<modbus::ReadBlock> limit_plan_;  // one read each, low first (as read alone)
  modbus::ReadbackSchedule readback_;
  ChamberMode mode_ = ChamberMode::off;        // read back last
  double product_c_ = 0, ramp_c_per_min_ = 0;  // read back last
  bool run_enabled_ = false;
};

}  // namespace station::drivers
