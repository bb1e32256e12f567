// Counter-board driver: latch protocol (SYNC, STATUS+COUNTS+TEMPS+DISCHARGE) and delta maths.
#include "drivers/counters/counter_boards.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "drivers/counters/counter_frames.hpp"

namespace station::drivers::counters {

using Clock = std::chrono::steady_clock;

struct CounterBoards::SlotState {
  // Across ticks: the last good latch.
  bool has_prev = false;
  std::uint32_t prev_up = 0, prev_down = 0, prev_time_us = 0;
  int ticks_since_prev = 0;  // latch intervals attempted or skipped since the last good latch
  // This tick.
  bool attributing = false;   // a STATUS naming the current latch has arrived
  bool stale_status = false;  // a stale STATUS arrived after it (repeats are then stale)
  std::optional<StatusFrame> status;
  std::optional<CountsFrame> counts;
  std::optional<TempsFrame> temps;
  std::optional<DischargeFrame> discharge;
  int duplicates = 0, stale = 0, corrupt = 0;

  void start_tick() {
    attributing = stale_status = false;
    status.reset();
    counts.reset();
    temps.reset();
    discharge.reset();
    duplicates = stale = corrupt = 0;
  }
  bool complete() const {
    if (!status || !counts) return false;
    if ((status->follows & kFollowsTemps) && !temps) return false;
    return !((status->follows & kFollowsDischarge) && !discharge);
  }
};

CounterBoards::CounterBoards(std::unique_ptr<can::CanTransport> transport,
                             CounterBoardsConfig config)
    : transport_(std::move(transport)), config_(std::move(config)) {
  if (!transport_) throw std::invalid_argument("counter boards: no CAN transport");
  if (config_.slots.empty()) throw std::invalid_argument("counter boards: no slots configured");
  if (!(config_.nominal_interval_s > 0))
    throw std::invalid_argument("counter boards: nominal_interval_s must be > 0");
  for (std::size_t i = 0; i < config_.slots.size(); ++i) {
    const auto& s = config_.slots[i];
    if (s.node < 1 || s.node > kMaxNode)
      throw std::invalid_argument(
          fmt::format("counter boards: slot {} node {} not in 1..{}", i, s.node, kMaxNode));
    if (!(s.pulse_weight_arcsec > 0))
      throw std::invalid_argument(fmt::format("counter boards: slot {} pulse weight <= 0", i));
    for (std::size_t j = 0; j < i; ++j)
      if (config_.slots[j].node == s.node)
        throw std::invalid_argument(
            fmt::format("counter boards: node {} in slots {} and {}", s.node, j, i));
  }
  state_.resize(config_.slots.size());
}

CounterBoards::~CounterBoards() = default;

Result<TickResult> CounterBoards::tick(std::uint8_t latch_seq) {
  if (auto s = send_sync(latch_seq); !s) return s.error();
  return collect(config_.tick_timeout);
}

Result<void> CounterBoards::send_sync(std::uint8_t latch_seq) {
  latch_seq_ = latch_seq;
  // Counted here, before any I/O, so a failed send or collect still spans its interval: the next
  // good latch's counts cover the real time since the last good one.
  for (auto& s : state_) {
    s.start_tick();
    ++s.ticks_since_prev;
  }
  return transport_->send(encode(SyncFrame{latch_seq}));
}

void CounterBoards::forget_latches() {
  for (auto& s : state_) {
    s.has_prev = false;
    s.ticks_since_prev = 0;
  }
}

void CounterBoards::note_skipped_ticks(int n) {
  if (n <= 0) return;
  for (auto& s : state_) s.ticks_since_prev += n;
}

Result<TickResult> CounterBoards::collect(std::chrono::milliseconds timeout) {
  TickResult out;
  out.latch_seq = latch_seq_;
  const auto deadline = Clock::now() + timeout;
  while (!all_complete()) {
    auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
    if (!config_.wall_clock_deadline)
      left = std::chrono::milliseconds(0);  // the log decides
    else if (left.count() <= 0)
      break;
    auto f = transport_->receive(left);
    if (f) {
      handle(f.value(), out);
    } else if (f.error().kind == ErrorKind::protocol) {
      ++out.corrupt_frames;  // a record that is not a can_frame: count it and keep listening
      out.last_error = f.error().message;
    } else if (f.error().kind == ErrorKind::timeout) {
      break;
    } else {
      return f.error();
    }
  }
  finish(out);
  return out;
}

bool CounterBoards::all_complete() const {
  return std::all_of(state_.begin(), state_.end(), [](const SlotState& s) { return s.complete(); });
}

namespace {

// Stores `value` in `slot` unless already present (then it is a duplicate).
template <typename T>
void keep_first(std::optional<T>& slot, T value, int& repeats) {
  if (slot)
    ++repeats;
  else
    slot = std::move(value);
}

}  // namespace

CounterBoards::SlotState* CounterBoards::slot_for(std::uint8_t node) {
  for (std::size_t i = 0; i < config_.slots.size(); ++i)
    if (config_.slots[i].node == node) return &state_[i];
  return nullptr;
}

void CounterBoards::handle(const can_frame& f, TickResult& out) {
  std::uint8_t node = 0;
  auto kind = classify(f, &node);
  SlotState* s = slot_for(node_bits(f.can_id));  // attribute even a bad frame by its ID bits
  auto bad = [&](const Error& e) {
    ++out.corrupt_frames;
    out.last_error = e.message;
    if (s) ++s->corrupt;
  };
  if (!kind) return bad(kind.error());
  if (kind.value() == FrameKind::sync) return;  // our own SYNC echoed by a real bus
  if (!s) return void(++out.unknown_frames);
  auto take = [&](auto decoded, auto& slot) {
    if (!decoded) return bad(decoded.error());
    if (!s->attributing) return void(++s->stale);
    // After a late stale STATUS, a second copy is more likely its follower than a duplicate.
    keep_first(slot, std::move(decoded).value(), s->stale_status ? s->stale : s->duplicates);
  };
  switch (kind.value()) {
    case FrameKind::status: {
      auto st = decode_status(f);
      if (!st) return bad(st.error());
      // Only the current latch's STATUS switches attribution on; a stale one never switches it
      // off again, or a late STATUS would make the current COUNTS look stale.
      if (st.value().latch_seq != latch_seq_) {
        ++s->stale;
        s->stale_status = s->attributing;
        return;
      }
      s->attributing = true;
      s->stale_status = false;
      return keep_first(s->status, std::move(st).value(), s->duplicates);
    }
    case FrameKind::counts:
      return take(decode_counts(f), s->counts);
    case FrameKind::temps:
      return take(decode_temps(f), s->temps);
    case FrameKind::discharge:
      return take(decode_discharge(f), s->discharge);
    case FrameKind::sync:
      return;
  }
}

namespace {

// Half the period of a wrapping u32 microsecond clock, s: gaps shorter than this tell "went
// backwards" from "wrapped" unambiguously.
constexpr double kHalfClockPeriodS = 2147.483648;

// Decides whether this latch chains to the previous good one. Counts are cumulative, so a delta
// is only meaningful when the board provably kept counting: no counter-reset flag, neither the
// counters nor the board clock went backwards (a restart), and the board clock advanced by the
// nominal span (nominal interval * intervals spanned) to within half of it. The clock wraps every
// 2^32 us (71.6 min), so a gap that long cannot be proven continuous: it is re-baselined.
LatchChain chain_of(const CounterReading& r, std::uint32_t prev_time_us, double nominal_s) {
  const double span_s = nominal_s * r.intervals_spanned;
  const std::uint32_t dt_us = r.board_time_us - prev_time_us;
  const bool backwards = static_cast<std::int32_t>(dt_us) < 0 ||
                         static_cast<std::int32_t>(r.delta_up) < 0 ||
                         static_cast<std::int32_t>(r.delta_down) < 0;
  if ((r.status_flags & kFlagCounterReset) || (span_s < kHalfClockPeriodS && backwards))
    return LatchChain::reset;
  const double board_s = dt_us * 1e-6;
  return std::abs(board_s - span_s) < 0.5 * span_s ? LatchChain::continuous : LatchChain::unproven;
}

// Fills net pulses, angle, interval and rate of a chained reading whose deltas are set.
void fill_delta(CounterReading& r, std::uint32_t prev_time_us, double pulse_weight_arcsec) {
  r.has_delta = true;
  r.net_pulses = static_cast<std::int64_t>(r.delta_up) - static_cast<std::int64_t>(r.delta_down);
  r.angle_arcsec = static_cast<double>(r.net_pulses) * pulse_weight_arcsec;
  r.interval_from_board_time = true;
  r.interval_s = static_cast<std::uint32_t>(r.board_time_us - prev_time_us) * 1e-6;
  r.rate_dph = r.angle_arcsec / r.interval_s;  // arcsec/s == deg/h
}

}  // namespace

void CounterBoards::finish(TickResult& out) {
  out.readings.clear();
  for (std::size_t i = 0; i < state_.size(); ++i) {
    SlotState& s = state_[i];
    CounterReading r;
    r.node = config_.slots[i].node;
    r.serial = config_.slots[i].serial;
    r.duplicate_frames = s.duplicates;
    r.stale_frames = s.stale;
    r.corrupt_frames = s.corrupt;
    r.answered = s.status && s.counts;
    r.latch_lost = !r.answered;
    if (r.answered) fill_reading(s, config_.slots[i], r);
    out.readings.push_back(std::move(r));
  }
}

void CounterBoards::fill_reading(SlotState& s, const CounterSlot& slot, CounterReading& r) {
  r.status_flags = s.status->flags;
  r.board_time_us = s.status->board_time_us;
  r.temps_missing = (s.status->follows & kFollowsTemps) && !s.temps;
  r.discharge_missing = (s.status->follows & kFollowsDischarge) && !s.discharge;
  if (s.temps)
    for (std::size_t k = 0; k < s.temps->count; ++k)
      r.temps_c.push_back(s.temps->centi_c[k] == std::numeric_limits<std::int16_t>::min()
                              ? std::numeric_limits<double>::quiet_NaN()  // 0x8000: no value
                              : s.temps->centi_c[k] * kTempScaleC);
  if (s.discharge) r.discharge_ua = s.discharge->leg_ua;
  // Unsigned subtraction makes the 2^32 counter wrap harmless as long as fewer than 2^32
  // pulses pass between good latches.
  r.delta_up = s.counts->up - s.prev_up;
  r.delta_down = s.counts->down - s.prev_down;
  r.intervals_spanned = s.ticks_since_prev;
  // A reset or an unprovable gap breaks the cumulative chain: re-baseline, report no delta.
  if (s.has_prev) {
    r.chain = chain_of(r, s.prev_time_us, config_.nominal_interval_s);
    if (r.chain == LatchChain::continuous) fill_delta(r, s.prev_time_us, slot.pulse_weight_arcsec);
  }
  if (!r.has_delta) r.delta_up = r.delta_down = 0, r.intervals_spanned = 0;
  s.has_prev = true;
  s.prev_up = s.counts->up;
  s.prev_down = s.counts->down;
  s.prev_time_us = r.board_time_us;
  s.ticks_since_prev = 0;
}

}  // namespace station::drivers::counters
