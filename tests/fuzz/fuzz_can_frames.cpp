// Fuzz target: the counter-board frame codec (drivers/counters/counter_frames.*). Input: the
// bytes of one struct can_frame as a socket delivers it (16 bytes; shorter is zero-padded).
// Property: no crash or UB; a frame that decodes re-encodes to the same ID, DLC and data.
#include <linux/can.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "drivers/counters/counter_frames.hpp"
#include "fuzz_check.hpp"

namespace wire = station::drivers::counters;
using station::fuzz::check;

namespace {

// The bytes a decoder reads: ID, DLC and the first DLC data bytes (but `ignored`, the index of
// a reserved byte the format says to ignore, or -1).
bool same_frame(const can_frame& a, const can_frame& b, int ignored) {
  can_frame x = a, y = b;
  if (ignored >= 0) x.data[ignored] = y.data[ignored] = 0;
  return x.can_id == y.can_id && x.can_dlc == y.can_dlc &&
         std::memcmp(x.data, y.data, std::min<std::size_t>(x.can_dlc, CAN_MAX_DLEN)) == 0;
}

template <typename Decoded>
void round_trip(const can_frame& f, const station::drivers::Result<Decoded>& d, const char* kind,
                int ignored = -1) {
  if (!d) return;
  check(same_frame(wire::encode(d.value()), f, ignored),
        std::string(kind) + " does not round-trip (a frame the codec accepts but cannot be)");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  can_frame f{};
  std::memcpy(&f, data, std::min(size, sizeof f));
  std::uint8_t node = 0;
  const auto kind = wire::classify(f, &node);
  // Every decoder must reject what is not its frame; run all of them on every input.
  round_trip(f, wire::decode_sync(f), "SYNC");
  round_trip(f, wire::decode_status(f), "STATUS", 7);  // byte 7: reserved, ignored
  round_trip(f, wire::decode_counts(f), "COUNTS");
  round_trip(f, wire::decode_temps(f), "TEMPS");
  round_trip(f, wire::decode_discharge(f), "DISCHARGE");
  if (kind) check(node <= wire::kMaxNode, "classify gave a node above 16");
  return 0;
}
