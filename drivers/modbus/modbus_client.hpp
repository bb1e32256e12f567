// A small Modbus client: reads and writes register-map points as one bounded transaction each,
// translating libmodbus/errno failures into ErrorKind in one place and reconnecting after loss
// (a lost connection, or kTimeoutsBeforeReconnect timeouts in a row on TCP) with bounded
// exponential back-off between failed attempts.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "drivers/common/link_state.hpp"
#include "drivers/common/result.hpp"
#include "drivers/common/stale_link.hpp"
#include "drivers/common/tap.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "drivers/modbus/modbus_wire.hpp"
#include "drivers/modbus/read_plan.hpp"
#include "drivers/modbus/register_map.hpp"

namespace station::drivers::modbus {

/// Translates a libmodbus/errno code from a failed call into a typed Error (the one place).
Error translate_modbus_error(int err, const std::string& what);

/// Modbus master for one endpoint. Not thread-safe; one caller at a time.
class ModbusClient {
 public:
  /// Stores the parameters; no I/O. `device` names the transport in errors and tap records.
  ModbusClient(std::string device, Endpoint endpoint, double response_timeout_s = 0.5);
  /// The same over another link (a recorded session in replay); `endpoint` still says what the
  /// link stands for (messages; TCP's reconnect after repeated timeouts).
  ModbusClient(std::string device, Endpoint endpoint, std::unique_ptr<ModbusWire> wire,
               double response_timeout_s = 0.5);
  ~ModbusClient();
  ModbusClient(ModbusClient&&) = default;
  ModbusClient& operator=(ModbusClient&&) = default;

  /// Sets the tap every exchange passes (nullptr: none). Not owned.
  void set_tap(Tap* tap) { tap_ = tap; }
  /// Sets the time source of the reconnect back-off (nullptr: steady clock). Not owned.
  void set_clock(const Clock* clock) { state_.set_clock(clock); }
  /// Opens the transport (TCP connect / open the serial line) now, whatever the back-off says;
  /// blocks up to the timeout.
  Result<void> connect();
  /// Closes the transport; the next read/write reconnects.
  void disconnect();
  /// True while the transport is open.
  bool connected() const { return state_.connected(); }
  /// Successful connects so far (a change tells a driver the device may have restarted).
  std::uint64_t connects() const { return state_.connects(); }

  /// Every read and write below first reopens a lost transport: at once after the loss, then
  /// after 0.5, 1, 2, 4, 8, 8 ... s of failed attempts (Backoff); while no attempt is due they
  /// return ErrorKind::disconnected without I/O.
  /// Reads one point's engineering value; blocks up to the response timeout.
  Result<double> read(const Point& p);
  /// Writes one rw point (function 6 for one word, 16 for two); blocks up to the timeout.
  Result<void> write(const Point& p, double value);
  /// Reads `points` with the block reads of `plan` (from plan_reads) and decodes each with the
  /// shared codec; values in the order of `points`. A non-finite value is a protocol error. With
  /// a pipeline (set_pipeline), up to that many block reads are on the wire at once.
  Result<std::vector<double>> read_points(std::span<const Point> points,
                                          std::span<const ReadBlock> plan);
  /// Reads `count` raw registers (function 3 or 4) at a PDU address; blocks up to the timeout.
  Result<std::vector<std::uint16_t>> read_registers(FunctionCode fc, int unit, std::uint16_t addr,
                                                    int count);
  /// Writes raw holding registers at a PDU address; blocks up to the timeout.
  Result<void> write_registers(int unit, std::uint16_t addr, std::span<const std::uint16_t> words);

  /// Name given at construction.
  const std::string& device() const { return device_; }
  /// Response timeout in seconds.
  double response_timeout_s() const { return timeout_s_; }
  /// Keeps at least `gap_s` seconds of quiet between one exchange and the next request (a
  /// dialect's pause on a serial line, drivers/registry/dialects.cpp); 0: none. No I/O.
  void set_request_gap_s(double gap_s) {
    gap_s_ = gap_s;
    wire_->set_request_gap_s(gap_s);
  }
  /// Lets read_points have up to `max_outstanding` block reads on the wire before the first
  /// reply (ModbusWire::read_batch; [chamber]/[turntable] `modbus_pipeline`); 1, the default:
  /// one request, its reply, the next. Below 1 counts as 1. No I/O.
  void set_pipeline(int max_outstanding) { pipeline_ = max_outstanding < 1 ? 1 : max_outstanding; }
  /// The most block reads read_points has outstanding at once.
  int pipeline() const { return pipeline_; }
  /// The pause set by set_request_gap_s, seconds.
  double request_gap_s() const { return gap_s_; }
  /// True once the unit itself answered (a reply or its own exception) since the link opened.
  bool unit_answered() const { return unit_answered_; }

 private:
  Result<void> ensure_connected();
  /// The block reads of `group`: one read_registers, or all sent as one batch (read_batch).
  Result<std::vector<std::vector<std::uint16_t>>> read_group(std::span<const ReadBlock> group);
  /// The tap records of a read request and of its reply.
  void tap_read_request(FunctionCode fc, int unit, std::uint16_t addr, int count);
  void read_answered(FunctionCode fc, int unit, std::uint16_t addr,
                     std::span<const std::uint16_t> words);
  Error fail(int err, int unit, const std::string& what);
  std::string unit_hint(int err, int unit) const;
  void tap(TapDirection dir, const char* kind, std::vector<std::uint8_t> bytes, std::string detail);

  std::string device_;
  Endpoint endpoint_;
  double timeout_s_;
  double gap_s_ = 0;
  int pipeline_ = 1;            ///< most block reads outstanding at once (set_pipeline)
  bool unit_answered_ = false;  ///< the unit answered since the link opened
  std::unique_ptr<ModbusWire> wire_;
  Tap* tap_ = nullptr;
  StaleLink link_;   ///< the stale-link rule (drivers/common/stale_link.hpp)
  LinkState state_;  ///< open or not, and when the next connect attempt is due
};

}  // namespace station::drivers::modbus
