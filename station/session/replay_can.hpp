// The replay transports (with replay_modbus, replay_ascii, replay_gpio): a CAN transport that
// plays back a recorded candump log (gpsd's idea: replay is a device), so a
// recorded session goes through the same counter-board driver again.
#pragma once

#include <vector>

#include "drivers/can/can_transport.hpp"
#include "drivers/can/candump_log.hpp"

namespace station {

/// Plays back `records`: sending a SYNC moves to just after the next logged SYNC with the same
/// latch sequence; receive() then yields the logged frames up to the following SYNC. No I/O.
class ReplayCanTransport final : public drivers::can::CanTransport {
 public:
  explicit ReplayCanTransport(std::vector<drivers::can::CandumpRecord> records);

  /// Non-SYNC frames are accepted and dropped; a SYNC not in the rest of the log is
  /// ErrorKind::disconnected (the log has ended).
  drivers::Result<void> send(const can_frame& frame) override;
  /// The next logged frame of this latch, or ErrorKind::timeout at the next SYNC / the end.
  drivers::Result<can_frame> receive(std::chrono::milliseconds timeout) override;
  int fd() const override { return -1; }
  double last_rx_time_s() const override { return last_rx_time_s_; }
  /// SYNC frames sent so far (ticks the replay has started).
  std::size_t syncs_sent() const { return syncs_sent_; }
  /// The records played back or skipped so far.
  std::vector<drivers::can::CandumpRecord> consumed() const {
    return {records_.begin(), records_.begin() + static_cast<std::ptrdiff_t>(cursor_)};
  }

 private:
  std::vector<drivers::can::CandumpRecord> records_;
  std::size_t cursor_ = 0;
  std::size_t syncs_sent_ = 0;
  double last_rx_time_s_ = 0;
};

/// The latch sequences of the SYNC frames in `records`, in order.
std::vector<std::uint8_t> logged_syncs(const std::vector<drivers::can::CandumpRecord>& records);

}  // namespace station
