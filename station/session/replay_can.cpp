// Replay of candump logs as a CAN transport.
#include "station/session/replay_can.hpp"

#include <fmt/format.h>

namespace station {
using drivers::ErrorKind;
using drivers::make_error;
using drivers::Result;
using drivers::can::CandumpRecord;
namespace {

constexpr canid_t kSyncId = 0x080;  // schemas/can_frames.md

bool is_sync(const can_frame& f) {
  return (f.can_id & CAN_EFF_MASK) == kSyncId && f.len >= 1;
}

}  // namespace

ReplayCanTransport::ReplayCanTransport(std::vector<CandumpRecord> records)
    : records_(std::move(records)) {}

Result<void> ReplayCanTransport::send(const can_frame& frame) {
  if (!is_sync(frame)) return {};
  for (std::size_t i = cursor_; i < records_.size(); ++i) {
    if (is_sync(records_[i].frame) && records_[i].frame.data[0] == frame.data[0]) {
      cursor_ = i + 1;
      ++syncs_sent_;
      return {};
    }
  }
  return make_error(ErrorKind::disconnected,
                    fmt::format("replay: no SYNC {} left in the log", frame.data[0]));
}

Result<can_frame> ReplayCanTransport::receive(std::chrono::milliseconds) {
  if (cursor_ >= records_.size() || is_sync(records_[cursor_].frame)) {
    return make_error(ErrorKind::timeout, "replay: no more frames for this latch");
  }
  const auto& r = records_[cursor_++];
  last_rx_time_s_ = static_cast<double>(r.time_sec) + 1e-6 * static_cast<double>(r.time_usec);
  return r.frame;
}

std::vector<std::uint8_t> logged_syncs(const std::vector<CandumpRecord>& records) {
  std::vector<std::uint8_t> out;
  for (const auto& r : records) {
    if (is_sync(r.frame)) out.push_back(r.frame.data[0]);
  }
  return out;
}

}  // namespace station
