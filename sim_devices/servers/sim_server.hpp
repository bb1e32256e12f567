// What every simulated device server offers the fault commands, whatever it speaks (Modbus
// over TCP/RTU, ASCII lines over TCP/pty): its endpoint and the same injected link faults.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>
#include <utility>

#include "sim_devices/servers/fault_schedule.hpp"

namespace station::sim {

/// A served simulated device: its endpoint, and the injected link faults every server takes the
/// same way (FaultSchedule: the server's thread asks it what each request gets).
class SimServer {
 public:
  virtual ~SimServer() = default;
  /// Endpoint string for the station's configuration (tcp://..., rtu:/dev/pts/N?..., serial:...).
  virtual std::string endpoint() const = 0;
  /// Requests received so far (including faulted ones).
  virtual std::uint64_t requests() const = 0;
  /// Stops serving; idempotent.
  virtual void stop() = 0;

  /// The clock the durations below run on (seconds): the steady clock unless set; a simulated
  /// rig sets its own time, so `stall 3` is three seconds of the run on either.
  void set_time_source(std::function<double()> now_s) { faults_.set_time_source(std::move(now_s)); }
  /// The next `n` requests get no reply at all (the client times out).
  void inject_timeouts(int n) { faults_.inject_timeouts(n); }
  /// The next `n` requests (n < 0: every one until clear_faults) get the device's own error
  /// reply: a Modbus exception `code`, or the ASCII dialect's error line.
  void inject_exception(int code, int n = 1) { faults_.inject_exception(code, n); }
  /// The next `n` requests make the server close the connection without replying (on a serial
  /// line: no reply).
  void inject_drop(int n = 1) { faults_.inject_drop(n); }
  /// Every request in the next `seconds` gets the device's refusal (the error reply of an
  /// exception `code`); 0 ends it.
  void refuse_for(double seconds, int code) { faults_.refuse_for(seconds, code); }
  /// Every request in the next `seconds` gets no reply; 0 ends a stall.
  void stall_for(double seconds) { faults_.stall_for(seconds); }
  /// Every reply sent in the next `seconds` leaves one byte every `byte_interval_s` (a slow
  /// proxy or a line that drips), the replies behind it queued in order; 0 s ends it (bytes
  /// already queued still drip).
  void drip_for(double seconds, double byte_interval_s) {
    faults_.drip_for(seconds, byte_interval_s);
  }
  /// Closes every connection now and refuses new ones for `seconds` (a powered-off device; a
  /// serial line is silent), then listens again on the same port.
  void disconnect_for(double seconds) { faults_.disconnect_for(seconds); }
  /// Ends every injected fault (timeouts, exceptions, drops, stall, drip, disconnect).
  void clear_faults() { faults_.clear(); }

  /// Returns once the server thread has done what the schedule says for now: every disconnect
  /// asked applied (connections and listener closed), the listener reopened when the down time
  /// is over (TCP; at most 1 s, then a line on stderr). A simulated clock jumps between ticks
  /// faster than the thread polls: settling after each jump makes a link fault last the same
  /// ticks on every run of a seed.
  void settle() const {
    using namespace std::chrono_literals;
    for (int i = 0; i < 1000 && tcp_.load(); ++i) {
      double down_until_s = 0;
      const std::uint64_t asked = faults_.kicks(down_until_s);
      if (asked == kicks_applied_.load() && (listening_.load() || faults_.now_s() < down_until_s))
        return;
      std::this_thread::sleep_for(1ms);
    }
    if (tcp_.load()) std::fputs("simulator: a server did not settle within 1 s\n", stderr);
  }

 protected:
  FaultSchedule faults_;
  std::atomic<bool> tcp_{false};        ///< serving TCP (a listener the faults close and reopen)
  std::atomic<bool> listening_{false};  ///< the TCP listener is open now
  std::atomic<std::uint64_t> kicks_applied_{0};  ///< disconnects the thread has carried out
};

}  // namespace station::sim
