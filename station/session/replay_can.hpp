// The replay transports (with replay_modbus, replay_ascii, replay_gpio): a CAN transport that
// plays back a recorded candump log (gpsd's idea: replay is a device), so a
// recorded session goes through the same counter-board driver again.
#pragma once

#include <memory>
#include <vector>

#include "drivers/can/can_transport.hpp"
#include "drivers/can/candump_log.hpp"
#include "station/session/replay_feed.hpp"

namespace station {

/// Plays back `records`: sending a SYNC moves to just after the next logged SYNC with the same
/// latch sequence; receive() then yields the logged frames up to the following SYNC. No I/O.
class ReplayCanTransport final : public drivers::can::CanTransport {
 public:
  explicit ReplayCanTransport(std::vector<drivers::can::CandumpRecord> records);
  /// The records as the replay pulls them from can.log.
  explicit ReplayCanTransport(std::shared_ptr<ReplayFeed<drivers::can::CandumpRecord>> records);

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
  const std::vector<drivers::can::CandumpRecord>& consumed() const { return records_->consumed(); }

 private:
  std::shared_ptr<ReplayFeed<drivers::can::CandumpRecord>> records_;
  std::size_t syncs_sent_ = 0;
  double last_rx_time_s_ = 0;
};

/// The latch sequences of the SYNC frames in `records`, in order.
std::vector<std::uint8_t> logged_syncs(const std::vector<drivers::can::CandumpRecord>& records);

/// Whether `frame` is a SYNC (schemas/can_frames.md): a tick's start.
bool is_sync_frame(const can_frame& frame);

}  // namespace station
