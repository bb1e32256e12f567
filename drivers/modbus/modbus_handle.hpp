// Move-only RAII holder for libmodbus contexts.
#pragma once

#include <modbus/modbus.h>

#include <memory>

#include "drivers/modbus/endpoint.hpp"

namespace station::drivers::modbus {

/// Deleter: closes the connection, then frees the context.
struct ModbusFree {
  void operator()(modbus_t* c) const noexcept {
    modbus_close(c);
    modbus_free(c);
  }
};

/// Owns one modbus_t*; move-only.
using ModbusHandle = std::unique_ptr<modbus_t, ModbusFree>;

/// Creates (does not connect) a context for the endpoint; throws std::runtime_error if libmodbus
/// rejects the parameters. No I/O.
ModbusHandle make_context(const Endpoint& ep);

}  // namespace station::drivers::modbus
