// libmodbus as a ModbusWire: one context per open link, both timeouts set.
#include "drivers/modbus/modbus_wire.hpp"

#include <cerrno>
#include <cmath>
#include <thread>

namespace station::drivers::modbus {

int LibmodbusWire::open(double timeout_s) {
  ctx_ = make_context(endpoint_);
  const double whole = std::floor(timeout_s);
  const auto sec = static_cast<std::uint32_t>(whole);
  const auto usec = static_cast<std::uint32_t>(std::lround((timeout_s - whole) * 1e6));
  modbus_set_response_timeout(ctx_.get(), sec, usec);
  // libmodbus waits byte_timeout (default 0.5 s) for each later chunk of a reply: a device that
  // sends part of a reply and stalls would hold the call that long whatever the response
  // timeout. The same bound applies to both (found by fuzz_modbus_replies). Never 0: libmodbus
  // reads a zero byte timeout as "wait forever".
  modbus_set_byte_timeout(ctx_.get(), sec, usec);
  if (modbus_connect(ctx_.get()) == -1) {
    const int err = errno;
    ctx_.reset();
    errno = err;
    return -1;
  }
  return 0;
}

void LibmodbusWire::rest() {
  if (gap_ > SteadyClock::duration::zero()) std::this_thread::sleep_until(last_end_ + gap_);
}

int LibmodbusWire::ended(int rc) {
  const int err = errno;
  last_end_ = SteadyClock::now();
  errno = err;
  return rc;
}

int LibmodbusWire::read(FunctionCode fc, int unit, std::uint16_t addr, int count,
                        std::uint16_t* dest) {
  if (!ctx_) {
    errno = ENOTCONN;
    return -1;
  }
  rest();
  modbus_set_slave(ctx_.get(), unit);
  return ended(fc == FunctionCode::holding
                   ? modbus_read_registers(ctx_.get(), addr, count, dest)
                   : modbus_read_input_registers(ctx_.get(), addr, count, dest));
}

int LibmodbusWire::write(int unit, std::uint16_t addr, std::span<const std::uint16_t> words) {
  if (!ctx_) {
    errno = ENOTCONN;
    return -1;
  }
  rest();
  modbus_set_slave(ctx_.get(), unit);
  const int n = static_cast<int>(words.size());
  return ended(n == 1 ? modbus_write_register(ctx_.get(), addr, words[0])
                      : modbus_write_registers(ctx_.get(), addr, n, words.data()));
}

void LibmodbusWire::flush() {
  if (ctx_) modbus_flush(ctx_.get());
}

}  // namespace station::drivers::modbus
