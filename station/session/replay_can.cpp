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

bool is_sync_frame(const can_frame& frame) {
  return is_sync(frame);
}

ReplayCanTransport::ReplayCanTransport(std::vector<CandumpRecord> records)
    : ReplayCanTransport(std::make_shared<ReplayFeed<CandumpRecord>>(std::move(records))) {}

ReplayCanTransport::ReplayCanTransport(std::shared_ptr<ReplayFeed<CandumpRecord>> records)
    : records_(std::move(records)) {}

Result<void> ReplayCanTransport::send(const can_frame& frame) {
  if (!is_sync(frame)) return {};
  for (std::size_t i = 0; const CandumpRecord* r = records_->peek(i); ++i) {
    if (is_sync(r->frame) && r->frame.data[0] == frame.data[0]) {
      for (std::size_t k = 0; k <= i; ++k) (void)records_->take();
      ++syncs_sent_;
      return {};
    }
  }
  return make_error(ErrorKind::disconnected,
                    fmt::format("replay: no SYNC {} left in the log", frame.data[0]));
}

Result<can_frame> ReplayCanTransport::receive(std::chrono::milliseconds) {
  const CandumpRecord* next = records_->peek();
  if (next == nullptr || is_sync(next->frame)) {
    return make_error(ErrorKind::timeout, "replay: no more frames for this latch");
  }
  const auto& r = records_->take();
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
