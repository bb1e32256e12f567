// Counter-board CAN codec and candump throughput (a 1 Mbit/s bus carries ~8,000 frames/s).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "drivers/can/candump_log.hpp"
#include "drivers/counters/counter_frames.hpp"

namespace c = station::drivers::counters;

namespace {

// One latch's answer from 16 boards: STATUS, COUNTS, TEMPS(3), DISCHARGE each.
std::vector<can_frame> bus_traffic() {
  std::vector<can_frame> out;
  for (std::uint8_t n = 1; n <= c::kMaxNode; ++n) {
    out.push_back(c::encode(c::StatusFrame{n, 42, 0, 123456789u * n, 0x07}));
    out.push_back(c::encode(c::CountsFrame{n, 0xFFFF0000u + n, 0x7FFF0000u + n}));
    out.push_back(c::encode(c::TempsFrame{n, 3, {2512, 2498, 2530, 0}}));
    out.push_back(c::encode(c::DischargeFrame{n, {650, 651}}));
  }
  return out;
}

// Classify + decode, the driver's per-frame work.
std::uint64_t decode_one(const can_frame& f) {
  std::uint8_t node = 0;
  auto k = c::classify(f, &node);
  if (!k) return 0;
  switch (k.value()) {
    case c::FrameKind::status:
      return c::decode_status(f).value().board_time_us;
    case c::FrameKind::counts:
      return c::decode_counts(f).value().up;
    case c::FrameKind::temps:
      return static_cast<std::uint64_t>(c::decode_temps(f).value().count);
    case c::FrameKind::discharge:
      return c::decode_discharge(f).value().leg_ua[0];
    case c::FrameKind::sync:
      return 1;
  }
  return 0;
}

}  // namespace

static void BM_CanDecodeFrames(benchmark::State& state) {
  const auto frames = bus_traffic();
  std::uint64_t sum = 0;
  for (auto _ : state) {
    for (const auto& f : frames) sum += decode_one(f);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(frames.size()));
}
BENCHMARK(BM_CanDecodeFrames);

static void BM_CanEncodeCounts(benchmark::State& state) {
  std::uint32_t up = 0;
  for (auto _ : state) {
    can_frame f = c::encode(c::CountsFrame{5, ++up, up / 2});
    benchmark::DoNotOptimize(f);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CanEncodeCounts);

static void BM_CanDecodeBadDlc(benchmark::State& state) {
  can_frame f = c::encode(c::CountsFrame{5, 1, 2});
  f.can_dlc = 3;
  for (auto _ : state) {
    auto r = c::decode_counts(f);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CanDecodeBadDlc);

static void BM_CandumpFormatParse(benchmark::State& state) {
  station::drivers::can::CandumpRecord r{1700000000, 123456, "can0",
                                         c::encode(c::CountsFrame{5, 0xDEADBEEF, 42})};
  for (auto _ : state) {
    auto back =
        station::drivers::can::parse_candump_line(station::drivers::can::format_candump_line(r));
    benchmark::DoNotOptimize(back);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CandumpFormatParse);
