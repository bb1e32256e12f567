// Context creation for either transport.
#include "drivers/modbus/modbus_handle.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace station::drivers::modbus {

ModbusHandle make_context(const Endpoint& ep) {
  modbus_t* ctx = nullptr;
  if (const auto* t = std::get_if<TcpEndpoint>(&ep)) {
    ctx = modbus_new_tcp_pi(t->host.c_str(), std::to_string(t->port).c_str());
  } else {
    const auto& r = std::get<RtuEndpoint>(ep);
    ctx = modbus_new_rtu(r.device.c_str(), r.baud, r.parity, r.data_bits, r.stop_bits);
  }
  if (ctx == nullptr)
    throw std::runtime_error("modbus context for '" + to_string(ep) +
                             "': " + modbus_strerror(errno));
  return ModbusHandle(ctx);
}

}  // namespace station::drivers::modbus
