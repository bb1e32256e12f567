// What every simulated device server offers the fault commands, whatever it speaks (Modbus
// over TCP/RTU, ASCII lines over TCP/pty): its endpoint and the same injected link faults.
#pragma once

#include <cstdint>
#include <string>

namespace station::sim {

/// A served simulated device.
class SimServer {
 public:
  virtual ~SimServer() = default;
  /// Endpoint string for the station's configuration (tcp://..., rtu:/dev/pts/N?..., serial:...).
  virtual std::string endpoint() const = 0;
  /// Requests received so far (including faulted ones).
  virtual std::uint64_t requests() const = 0;
  /// The next `n` requests get no reply at all (the client times out).
  virtual void inject_timeouts(int n) = 0;
  /// The next `n` requests (n < 0: every one until clear_faults) get the device's own error
  /// reply: a Modbus exception `code`, or the ASCII dialect's error line.
  virtual void inject_exception(int code, int n = 1) = 0;
  /// The next `n` requests make the server close the connection without replying.
  virtual void inject_drop(int n = 1) = 0;
  /// Every request in the next `seconds` (wall clock) gets no reply; 0 ends a stall.
  virtual void stall_for(double seconds) = 0;
  /// Closes every connection now and refuses new ones for `seconds` (a powered-off device).
  virtual void disconnect_for(double seconds) = 0;
  /// Ends every injected fault.
  virtual void clear_faults() = 0;
  /// Stops serving; idempotent.
  virtual void stop() = 0;
};

}  // namespace station::sim
