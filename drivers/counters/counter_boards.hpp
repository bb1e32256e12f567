// Driver of the RLG pulse-counter boards: SYNC each tick, collect answers, turn counts into angle.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/can/can_transport.hpp"
#include "drivers/common/result.hpp"

namespace station::drivers::counters {

/// One configured board position.
struct CounterSlot {
  std::uint8_t node = 1;             ///< CAN node id 1..16
  std::string serial;                ///< gyro serial number
  double pulse_weight_arcsec = 1.5;  ///< angle per net pulse, arcsec
};

/// Driver configuration. Validated by the constructor (throws std::invalid_argument).
struct CounterBoardsConfig {
  std::vector<CounterSlot> slots;
  std::chrono::milliseconds tick_timeout{200};  ///< longest wait for all answers of one latch
  double nominal_interval_s = 1.0;              ///< expected latch interval, s
  /// false for a replayed log: collect() ends when the transport has no more frames for the
  /// latch (ErrorKind::timeout), however much wall time that took; tick_timeout is then unused.
  bool wall_clock_deadline = true;
};

/// How a good latch relates to the board's previous good latch.
enum class LatchChain : std::uint8_t {
  first,       ///< no previous good latch: the baseline, no delta
  continuous,  ///< the board clock advanced by the span since the previous latch: delta valid
  reset,       ///< the board restarted (counter-reset flag, counts or clock went backwards)
  unproven,    ///< the board clock disagrees with the span (e.g. a long outage): re-baselined
};

/// One board's reading for one latch.
///
/// Sign convention: the up counter counts fringes of positive rotation (right-hand rule about
/// the input axis), the down counter negative; dither makes both run, only their difference
/// is angle: angle_arcsec = (delta_up - delta_down) * pulse_weight_arcsec.
struct CounterReading {
  std::uint8_t node = 0;
  std::string serial;
  bool answered = false;   ///< STATUS and COUNTS for this latch arrived
  bool has_delta = false;  ///< chained to a previous good latch, so the deltas mean something
  LatchChain chain = LatchChain::first;   ///< why there is (or is not) a delta
  bool latch_lost = false;                ///< no (complete) answer this tick; nothing is invented
  std::uint32_t delta_up = 0;             ///< up pulses since the previous good latch (mod 2^32)
  std::uint32_t delta_down = 0;           ///< down pulses since the previous good latch (mod 2^32)
  std::int64_t net_pulses = 0;            ///< delta_up - delta_down
  int intervals_spanned = 0;              ///< ticks covered by the delta (>1 after lost latches)
  double interval_s = 0;                  ///< time covered by the delta (board µs clock), s
  bool interval_from_board_time = false;  ///< always true with a delta (kept for callers)
  double angle_arcsec = 0;                ///< net_pulses * pulse weight, arcsec
  double rate_dph = 0;                    ///< angle_arcsec / interval_s (1 arcsec/s == 1 deg/h)
  std::uint8_t status_flags = 0;          ///< kFlag* bits from STATUS
  std::uint32_t board_time_us = 0;
  std::vector<double> temps_c;  ///< TEMPS channels, C (empty if none arrived)
  std::optional<std::array<std::uint32_t, 2>> discharge_ua;  ///< leg currents, µA
  bool temps_missing = false;      ///< STATUS announced TEMPS that did not arrive
  bool discharge_missing = false;  ///< STATUS announced DISCHARGE that did not arrive
  int duplicate_frames = 0;        ///< repeated frames for this latch (first one kept)
  int stale_frames = 0;            ///< frames answering an older latch (ignored)
  int corrupt_frames = 0;          ///< frames with this node's ID that failed to decode
};

/// All readings of one tick, plus bus-level problems.
struct TickResult {
  std::uint8_t latch_seq = 0;
  std::vector<CounterReading> readings;  ///< in slot order
  int corrupt_frames = 0;                ///< all frames that failed to decode this tick
  int unknown_frames = 0;                ///< valid frames from nodes not configured
  std::string last_error;                ///< message of the last decode problem, if any
};

/// The counter boards on one CAN bus. Not thread-safe; one tick at a time.
class CounterBoards {
 public:
  /// Validates config (throws std::invalid_argument); does no I/O.
  CounterBoards(std::unique_ptr<can::CanTransport> transport, CounterBoardsConfig config);
  ~CounterBoards();

  /// Sends SYNC with latch_seq and collects the answers; blocks at most tick_timeout.
  Result<TickResult> tick(std::uint8_t latch_seq);
  /// First half of tick(): sends the SYNC (non-blocking up to the send timeout). Every call
  /// counts as one latch interval for the next delta, even when the send or collect fails.
  Result<void> send_sync(std::uint8_t latch_seq);
  /// Second half of tick(): collects answers to the last SYNC; blocks at most `timeout`.
  Result<TickResult> collect(std::chrono::milliseconds timeout);
  /// The caller skipped `n` ticks (no SYNC sent, e.g. on overrun); no I/O, n <= 0 ignored.
  void note_skipped_ticks(int n);
  /// Forgets every board's previous latch (e.g. after a commissioning probe): the next good
  /// latch is a new baseline (LatchChain::first). No I/O.
  void forget_latches();
  /// The configuration in use.
  const CounterBoardsConfig& config() const { return config_; }

 private:
  struct SlotState;
  SlotState* slot_for(std::uint8_t node);
  void handle(const can_frame& f, TickResult& out);
  void fill_reading(SlotState& s, const CounterSlot& slot, CounterReading& r);
  bool all_complete() const;
  void finish(TickResult& out);

  std::unique_ptr<can::CanTransport> transport_;
  CounterBoardsConfig config_;
  std::vector<SlotState> state_;
  std::uint8_t latch_seq_ = 0;
};

}  // namespace station::drivers::counters
