// The raw Modbus link under ModbusClient, behind one small interface: libmodbus on a TCP socket
// or a serial line here; a recorded session answering from its log is the other implementation
// (replay). ModbusClient's error translation, reconnect and back-off run the same over both.
#pragma once

#include <cstdint>
#include <span>

#include "drivers/modbus/endpoint.hpp"
#include "drivers/modbus/modbus_handle.hpp"
#include "drivers/modbus/register_map.hpp"

namespace station::drivers::modbus {

/// One Modbus link. Calls return like libmodbus's: 0 / a count, or -1 with errno set.
class ModbusWire {
 public:
  virtual ~ModbusWire() = default;
  /// Opens the link, each wait of every later call bounded by `timeout_s`. May throw
  /// std::runtime_error for parameters the transport rejects (no I/O happened then).
  virtual int open(double timeout_s) = 0;
  /// Closes the link; nothing when it is closed.
  virtual void close() = 0;
  /// Reads `count` registers (function `fc`) of `unit` at PDU address `addr` into `dest`.
  virtual int read(FunctionCode fc, int unit, std::uint16_t addr, int count,
                   std::uint16_t* dest) = 0;
  /// Writes holding registers of `unit` at `addr` (function 6 for one word, 16 for more).
  virtual int write(int unit, std::uint16_t addr, std::span<const std::uint16_t> words) = 0;
  /// Discards unread input (after a timeout or a garbled reply).
  virtual void flush() = 0;
};

/// The real link: libmodbus over TCP or RTU. The constructor does no I/O.
class LibmodbusWire final : public ModbusWire {
 public:
  explicit LibmodbusWire(Endpoint endpoint) : endpoint_(std::move(endpoint)) {}
  int open(double timeout_s) override;
  void close() override { ctx_.reset(); }
  int read(FunctionCode fc, int unit, std::uint16_t addr, int count, std::uint16_t* dest) override;
  int write(int unit, std::uint16_t addr, std::span<const std::uint16_t> words) override;
  void flush() override;

 private:
  Endpoint endpoint_;
  ModbusHandle ctx_;
};

}  // namespace station::drivers::modbus
