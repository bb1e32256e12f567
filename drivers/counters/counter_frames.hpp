// Wire definitions of the RLG pulse-counter boards on CAN (schemas/can_frames.md): IDs and codecs.
// Shared by the driver (drivers/counters/counter_boards.*) and the simulator (sim_devices/).
#pragma once

#include <linux/can.h>

#include <array>
#include <cstdint>
#include <vector>

#include "drivers/common/result.hpp"

namespace station::drivers::counters {

/// SYNC identifier (CANopen SYNC), sent by the station once per tick.
inline constexpr canid_t kSyncId = 0x080;
/// Function code (bits 10..7 of the 11-bit ID) of each board frame; ID = function code + node.
inline constexpr canid_t kStatusFunction = 0x180;
inline constexpr canid_t kCountsFunction = 0x280;
inline constexpr canid_t kTempsFunction = 0x380;
inline constexpr canid_t kDischargeFunction = 0x480;
/// Mask selecting the function code of an 11-bit ID.
inline constexpr canid_t kFunctionMask = 0x780;
/// Node ids are 1..kMaxNode.
inline constexpr std::uint8_t kMaxNode = 16;
/// At most this many temperature channels in one TEMPS frame.
inline constexpr std::size_t kMaxTemps = 4;
/// Scale of TEMPS values: one count is 0.01 C.
inline constexpr double kTempScaleC = 0.01;

/// STATUS flag bits (byte 1).
inline constexpr std::uint8_t kFlagLaserFault = 0x01;       ///< laser discharge fault
inline constexpr std::uint8_t kFlagTempSensorFault = 0x02;  ///< a temperature sensor failed
inline constexpr std::uint8_t kFlagCounterReset =
    0x04;  ///< counters reset/overflowed since last latch
inline constexpr std::uint8_t kFlagDitherFault = 0x08;  ///< dither drive fault

/// STATUS "follows" bits (byte 6): which frames the board sends after this STATUS for the latch.
inline constexpr std::uint8_t kFollowsCounts = 0x01;
inline constexpr std::uint8_t kFollowsTemps = 0x02;
inline constexpr std::uint8_t kFollowsDischarge = 0x04;

/// Kind of a counter-board bus frame, from its ID.
enum class FrameKind : std::uint8_t { sync, status, counts, temps, discharge };

/// SYNC: the station asks every board to latch its counters (ID 0x080, DLC 1).
struct SyncFrame {
  std::uint8_t latch_seq = 0;  ///< latch sequence, wraps mod 256
};

/// STATUS: first answer to a SYNC (ID 0x180+node, DLC 8).
struct StatusFrame {
  std::uint8_t node = 0;
  std::uint8_t latch_seq = 0;       ///< the SYNC sequence this answer latched
  std::uint8_t flags = 0;           ///< kFlag* bits
  std::uint32_t board_time_us = 0;  ///< board clock at the latch, µs, wraps mod 2^32
  std::uint8_t follows = 0;         ///< kFollows* bits
};

/// COUNTS: cumulative up/down pulse counts at the latch (ID 0x280+node, DLC 8), wrap mod 2^32.
struct CountsFrame {
  std::uint8_t node = 0;
  std::uint32_t up = 0;
  std::uint32_t down = 0;
};

/// TEMPS: up to 4 temperatures at the latch (ID 0x380+node, DLC 2*count), int16 of 0.01 C.
struct TempsFrame {
  std::uint8_t node = 0;
  std::uint8_t count = 0;
  std::array<std::int16_t, kMaxTemps> centi_c{};  ///< value * 0.01 = C
};

/// DISCHARGE: the two laser leg currents at the latch (ID 0x480+node, DLC 8), u32 µA.
struct DischargeFrame {
  std::uint8_t node = 0;
  std::array<std::uint32_t, 2> leg_ua{};
};

/// Encoders: build a classic 11-bit data frame (never fail; node must be 1..kMaxNode).
can_frame encode(const SyncFrame& f);
can_frame encode(const StatusFrame& f);
can_frame encode(const CountsFrame& f);
can_frame encode(const TempsFrame& f);
can_frame encode(const DischargeFrame& f);

/// Classify an ID: kind and node (0 for SYNC); protocol error for unknown ID or node out of range.
Result<FrameKind> classify(const can_frame& f, std::uint8_t* node);
/// Node bits of an ID (0..127) without validation, for attributing bad frames.
inline std::uint8_t node_bits(canid_t id) {
  return static_cast<std::uint8_t>(id & 0x7F);
}

/// Decoders: protocol error naming the ID and what is wrong (bad DLC, wrong ID, node out of range).
Result<SyncFrame> decode_sync(const can_frame& f);
Result<StatusFrame> decode_status(const can_frame& f);
Result<CountsFrame> decode_counts(const can_frame& f);
Result<TempsFrame> decode_temps(const can_frame& f);
Result<DischargeFrame> decode_discharge(const can_frame& f);

/// Receive filters (id, mask) accepting every board frame and nothing else (CAN_RAW_FILTER).
std::vector<can_filter> board_frame_filters();

}  // namespace station::drivers::counters
