// Codec of the counter-board CAN frames: little-endian packing, ID/DLC/node validation.
#include "drivers/counters/counter_frames.hpp"

#include <fmt/format.h>

#include <cstring>

namespace station::drivers::counters {
namespace {

void put_u32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
  p[2] = static_cast<std::uint8_t>(v >> 16);
  p[3] = static_cast<std::uint8_t>(v >> 24);
}

std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

can_frame make_frame(canid_t id, std::uint8_t dlc) {
  can_frame f;
  std::memset(&f, 0, sizeof f);
  f.can_id = id;
  f.can_dlc = dlc;
  return f;
}

Error frame_error(const can_frame& f, const char* what) {
  return make_error(ErrorKind::protocol,
                    fmt::format("CAN frame id=0x{:03X} dlc={}: {}", f.can_id & CAN_EFF_MASK,
                                static_cast<int>(f.can_dlc), what));
}

// Checks that f is a classic data frame with the given function code, a valid node and a
// DLC in [min_dlc, max_dlc]; returns the node.
Result<std::uint8_t> check(const can_frame& f, canid_t function, std::uint8_t min_dlc,
                           std::uint8_t max_dlc) {
  if (f.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG))
    return frame_error(f, "extended, remote or error frame where a data frame was expected");
  if (f.can_id & ~CAN_SFF_MASK) return frame_error(f, "standard frame with ID bits above 11");
  if ((f.can_id & kFunctionMask) != function) return frame_error(f, "unexpected function code");
  const std::uint8_t node = node_bits(f.can_id);
  if (node < 1 || node > kMaxNode) return frame_error(f, "node out of range 1..16");
  if (f.can_dlc < min_dlc || f.can_dlc > max_dlc) return frame_error(f, "bad DLC");
  return node;
}

}  // namespace

can_frame encode(const SyncFrame& s) {
  can_frame f = make_frame(kSyncId, 1);
  f.data[0] = s.latch_seq;
  return f;
}

can_frame encode(const StatusFrame& s) {
  can_frame f = make_frame(kStatusFunction + s.node, 8);
  f.data[0] = s.latch_seq;
  f.data[1] = s.flags;
  put_u32(f.data + 2, s.board_time_us);
  f.data[6] = s.follows;
  return f;
}

can_frame encode(const CountsFrame& c) {
  can_frame f = make_frame(kCountsFunction + c.node, 8);
  put_u32(f.data, c.up);
  put_u32(f.data + 4, c.down);
  return f;
}

can_frame encode(const TempsFrame& t) {
  const std::uint8_t n = t.count > kMaxTemps ? kMaxTemps : t.count;
  can_frame f = make_frame(kTempsFunction + t.node, static_cast<std::uint8_t>(2 * n));
  for (std::size_t i = 0; i < n; ++i) {
    const auto v = static_cast<std::uint16_t>(t.centi_c[i]);
    f.data[2 * i] = static_cast<std::uint8_t>(v);
    f.data[2 * i + 1] = static_cast<std::uint8_t>(v >> 8);
  }
  return f;
}

can_frame encode(const DischargeFrame& d) {
  can_frame f = make_frame(kDischargeFunction + d.node, 8);
  put_u32(f.data, d.leg_ua[0]);
  put_u32(f.data + 4, d.leg_ua[1]);
  return f;
}

Result<FrameKind> classify(const can_frame& f, std::uint8_t* node) {
  *node = 0;
  if (f.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG))
    return frame_error(f, "extended, remote or error frame on the counter bus");
  if (f.can_id & ~CAN_SFF_MASK) return frame_error(f, "standard frame with ID bits above 11");
  if (f.can_id == kSyncId) return FrameKind::sync;
  FrameKind kind;
  switch (f.can_id & kFunctionMask) {
    case kStatusFunction:
      kind = FrameKind::status;
      break;
    case kCountsFunction:
      kind = FrameKind::counts;
      break;
    case kTempsFunction:
      kind = FrameKind::temps;
      break;
    case kDischargeFunction:
      kind = FrameKind::discharge;
      break;
    default:
      return frame_error(f, "unknown ID");
  }
  const std::uint8_t n = node_bits(f.can_id);
  if (n < 1 || n > kMaxNode) return frame_error(f, "node out of range 1..16");
  *node = n;
  return kind;
}

Result<SyncFrame> decode_sync(const can_frame& f) {
  if (f.can_id != kSyncId) return frame_error(f, "not a SYNC ID");
  if (f.can_dlc != 1) return frame_error(f, "bad DLC (SYNC needs 1)");
  return SyncFrame{f.data[0]};
}

Result<StatusFrame> decode_status(const can_frame& f) {
  auto node = check(f, kStatusFunction, 8, 8);
  if (!node) return node.error();
  return StatusFrame{node.value(), f.data[0], f.data[1], get_u32(f.data + 2), f.data[6]};
}

Result<CountsFrame> decode_counts(const can_frame& f) {
  auto node = check(f, kCountsFunction, 8, 8);
  if (!node) return node.error();
  return CountsFrame{node.value(), get_u32(f.data), get_u32(f.data + 4)};
}

Result<TempsFrame> decode_temps(const can_frame& f) {
  auto node = check(f, kTempsFunction, 2, 2 * kMaxTemps);
  if (!node) return node.error();
  if (f.can_dlc % 2 != 0) return frame_error(f, "bad DLC (TEMPS needs an even DLC 2..8)");
  TempsFrame t;
  t.node = node.value();
  t.count = static_cast<std::uint8_t>(f.can_dlc / 2);
  for (std::size_t i = 0; i < t.count; ++i)
    t.centi_c[i] = static_cast<std::int16_t>(f.data[2 * i] | f.data[2 * i + 1] << 8);
  return t;
}

Result<DischargeFrame> decode_discharge(const can_frame& f) {
  auto node = check(f, kDischargeFunction, 8, 8);
  if (!node) return node.error();
  return DischargeFrame{node.value(), {get_u32(f.data), get_u32(f.data + 4)}};
}

std::vector<can_filter> board_frame_filters() {
  std::vector<can_filter> out;
  for (canid_t fc : {kStatusFunction, kCountsFunction, kTempsFunction, kDischargeFunction})
    out.push_back(can_filter{fc, kFunctionMask | CAN_EFF_FLAG | CAN_RTR_FLAG});
  return out;
}

}  // namespace station::drivers::counters
