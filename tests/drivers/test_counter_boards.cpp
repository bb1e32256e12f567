// Counter-board driver against the simulated boards over a real SEQPACKET socketpair.
#include <gtest/gtest.h>
#include <sys/socket.h>

#include <cmath>
#include <stdexcept>

#include "drivers/counters/counter_boards.hpp"
#include "drivers/counters/counter_frames.hpp"
#include "sim_devices/counter_board_sim.hpp"

using namespace station::drivers;
using namespace std::chrono_literals;
namespace c = station::drivers::counters;
namespace sim = station::sim;

namespace {

constexpr double kPulseWeightArcsec = 1.5;
// Earth rate along a vertical input axis at 39.9 deg N: 15.04107 * sin(lat) deg/h (WGS-84 rate).
const double kEarthUpDph = 15.04107 * std::sin(39.9 * M_PI / 180.0);

sim::BoardConfig board_config(std::uint8_t node, std::uint64_t seed) {
  sim::BoardConfig b;
  b.node = node;
  b.gyro.seed = seed;
  b.gyro.earth_rate_dph = kEarthUpDph;
  b.gyro.pulse_weight_arcsec = kPulseWeightArcsec;
  return b;
}

// Driver and simulated bus on two ends of one socketpair, driven in lockstep.
struct Rig {
  std::unique_ptr<sim::CounterBoardBus> bus;
  std::unique_ptr<c::CounterBoards> driver;
  UniqueFd driver_side;  // a second descriptor of the driver's socket, to jam its tx queue
  double t_s = 0;

  explicit Rig(std::vector<sim::BoardConfig> boards) {
    int sv[2];
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0)
      throw std::runtime_error("socketpair");
    bus = std::make_unique<sim::CounterBoardBus>(sv[1]);
    c::CounterBoardsConfig cfg;
    for (const auto& b : boards) {
      bus->add_board(b);
      cfg.slots.push_back({b.node, "RLG-" + std::to_string(b.node), b.gyro.pulse_weight_arcsec});
    }
    driver_side = UniqueFd(::dup(sv[0]));
    driver = std::make_unique<c::CounterBoards>(can::make_fd_transport(UniqueFd(sv[0])), cfg);
  }
  // One second of simulated time, then one latch answered by the simulator.
  c::TickResult tick(std::uint8_t seq, double air_c = 25.0) {
    t_s += 1.0;
    bus->step_to(t_s, air_c);
    EXPECT_TRUE(driver->send_sync(seq).ok());
    bus->service(1000ms);
    auto r = driver->collect(100ms);  // answers are already queued: 100 ms only bounds a loss
    EXPECT_TRUE(r.ok()) << r.error().message;
    return r.value();
  }
};

}  // namespace

TEST(CounterBoards, ConfigIsValidatedWithoutIo) {
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
  ::close(sv[1]);
  auto make = [&](std::vector<c::CounterSlot> slots) {
    return c::CounterBoards(can::make_fd_transport(UniqueFd(::dup(sv[0]))), {slots});
  };
  EXPECT_THROW(make({{17, "x", 1.5}}), std::invalid_argument);
  EXPECT_THROW(make({{1, "x", 0.0}}), std::invalid_argument);
  EXPECT_THROW(make({{1, "x", 1.5}, {1, "y", 1.5}}), std::invalid_argument);
  EXPECT_NO_THROW(make({{1, "x", 1.5}}));  // the peer is closed: no I/O happened
  ::close(sv[0]);
}

// Pulses are floor(true angle / w), remainder carried, so each latch's pulse angle is within
// one pulse weight w of the true angle: the per-interval angle error is in (-w, w) and the
// rate error below w / interval (arcsec/s == deg/h): 1.5 deg/h at 1 s.
TEST(CounterBoards, RateMatchesTrueMeanRateWithinQuantisation) {
  Rig rig({board_config(1, 11), board_config(2, 22)});
  std::vector<double> prev_angle(2), first_angle(2);
  std::vector<std::int64_t> sum_pulses(2, 0);
  for (int k = 0; k < 300; ++k) {
    const double air_c = 25.0 + 20.0 / 3600.0 * k;  // 20 C/h ramp
    const c::TickResult r = rig.tick(static_cast<std::uint8_t>(k), air_c);
    ASSERT_EQ(r.readings.size(), 2u);
    for (int i = 0; i < 2; ++i) {
      const auto& rd = r.readings[i];
      const double angle = rig.bus->board(i + 1).gyro().true_angle_arcsec();
      ASSERT_TRUE(rd.answered);
      EXPECT_EQ(rd.has_delta, k > 0);
      if (k == 0) first_angle[i] = angle;
      if (k > 0) {
        EXPECT_TRUE(rd.interval_from_board_time);
        EXPECT_NEAR(rd.interval_s, 1.0, 1e-9);
        EXPECT_LT(std::abs(rd.rate_dph - (angle - prev_angle[i]) / 1.0), kPulseWeightArcsec);
        sum_pulses[i] += rd.net_pulses;
      }
      EXPECT_EQ(rd.temps_c.size(), 3u);
      EXPECT_NEAR(rd.temps_c[0], rig.bus->board(i + 1).gyro().temp_a_c(), 0.005);
      ASSERT_TRUE(rd.discharge_ua.has_value());
      prev_angle[i] = angle;
    }
  }
  for (int i = 0; i < 2; ++i) {
    // Over the whole run the error is still below one pulse: nothing accumulates.
    EXPECT_LT(std::abs(sum_pulses[i] * kPulseWeightArcsec - (prev_angle[i] - first_angle[i])),
              kPulseWeightArcsec);
    // Mean rate over 299 s near Earth rate + bias (noise sigma 0.18/sqrt(299) deg/h).
    EXPECT_NEAR(sum_pulses[i] * kPulseWeightArcsec / 299.0, kEarthUpDph + 0.05, 0.1);
  }
}

TEST(CounterBoards, CounterWrapLosesNothing) {
  auto b = board_config(3, 33);
  b.initial_up = 0xFFFFFFFFu - 30000;  // dither at 2e4 pulses/s wraps both within 2 s
  b.initial_down = 0xFFFFFFFFu - 45000;
  Rig rig({b});
  const auto& gyro = rig.bus->board(3).gyro();
  rig.tick(0);
  const std::int64_t net0 = gyro.net_pulses();
  std::int64_t sum = 0;
  for (int k = 1; k < 10; ++k) {
    const auto rd = rig.tick(static_cast<std::uint8_t>(k)).readings[0];
    ASSERT_TRUE(rd.has_delta);
    EXPECT_LT(rd.delta_up, 30000u);  // a mishandled wrap would show ~2^32
    EXPECT_LT(rd.delta_down, 30000u);
    sum += rd.net_pulses;
  }
  EXPECT_LT(rig.bus->board(3).up_count(), 1000000u);  // the counters did wrap
  EXPECT_EQ(sum, gyro.net_pulses() - net0);
}

TEST(CounterBoards, LostLatchIsFlaggedAndNextDeltaCoversTheGap) {
  Rig rig({board_config(1, 44), board_config(2, 55)});
  const auto& gyro = rig.bus->board(1).gyro();
  rig.tick(0);
  const std::int64_t net0 = gyro.net_pulses();
  rig.bus->board(1).set_answering(false);
  for (std::uint8_t k = 1; k <= 2; ++k) {
    const auto r = rig.tick(k);
    EXPECT_TRUE(r.readings[0].latch_lost);
    EXPECT_FALSE(r.readings[0].answered);
    EXPECT_EQ(r.readings[0].net_pulses, 0);  // nothing invented
    EXPECT_FALSE(r.readings[1].latch_lost);
  }
  rig.bus->board(1).set_answering(true);
  const auto rd = rig.tick(3).readings[0];
  ASSERT_TRUE(rd.has_delta);
  EXPECT_EQ(rd.intervals_spanned, 3);
  EXPECT_NEAR(rd.interval_s, 3.0, 1e-9);
  EXPECT_EQ(rd.net_pulses, gyro.net_pulses() - net0);  // exact: counts are cumulative
}

TEST(CounterBoards, LateAnswersAreStaleAndIgnored) {
  Rig rig({board_config(1, 66)});
  rig.tick(0);
  rig.t_s += 1.0;
  rig.bus->step_to(rig.t_s, 25.0);
  ASSERT_TRUE(rig.driver->send_sync(1).ok());
  auto missed = rig.driver->collect(20ms);  // the board has not been serviced yet
  ASSERT_TRUE(missed.ok());
  EXPECT_TRUE(missed.value().readings[0].latch_lost);
  rig.bus->service(1000ms);  // answers latch 1 late
  const auto rd = rig.tick(2).readings[0];
  EXPECT_EQ(rd.stale_frames, 4);  // STATUS, COUNTS, TEMPS, DISCHARGE of latch 1
  EXPECT_TRUE(rd.answered);
  EXPECT_EQ(rd.intervals_spanned, 2);
}

TEST(CounterBoards, DuplicatesAreReportedAndFirstKept) {
  Rig rig({board_config(1, 77)});
  rig.tick(0);
  rig.bus->board(1).duplicate_next_frames(4);
  const auto rd = rig.tick(1).readings[0];
  EXPECT_TRUE(rd.answered);
  // The tick ends once the latch is complete, so the copy of DISCHARGE (the last frame) is
  // read by the next tick, where it no longer matches the latch: stale, not duplicate.
  EXPECT_EQ(rd.duplicate_frames, 3);
  EXPECT_EQ(rd.intervals_spanned, 1);
  const auto next = rig.tick(2).readings[0];
  EXPECT_EQ(next.stale_frames, 1);
  EXPECT_EQ(next.duplicate_frames, 0);
  EXPECT_TRUE(next.answered);
}

TEST(CounterBoards, CorruptFramesAreCountedAndRecovered) {
  for (auto kind :
       {sim::CorruptKind::bad_dlc, sim::CorruptKind::garbage_id, sim::CorruptKind::short_record}) {
    Rig rig({board_config(1, 88)});
    const auto& gyro = rig.bus->board(1).gyro();
    rig.tick(0);
    const std::int64_t net0 = gyro.net_pulses();
    rig.bus->board(1).corrupt_next_frames(1, kind);  // hits STATUS: latch unattributable
    const auto bad = rig.tick(1);
    EXPECT_EQ(bad.corrupt_frames, 1);
    EXPECT_FALSE(bad.last_error.empty());
    EXPECT_TRUE(bad.readings[0].latch_lost);
    EXPECT_EQ(bad.readings[0].corrupt_frames, kind == sim::CorruptKind::short_record ? 0 : 1);
    const auto good = rig.tick(2).readings[0];
    EXPECT_EQ(good.intervals_spanned, 2);
    EXPECT_EQ(good.net_pulses, gyro.net_pulses() - net0);
  }
}

TEST(CounterBoards, FailedTempSensorIsFlaggedAndNotANumber) {
  Rig rig({board_config(1, 99)});
  rig.bus->board(1).fail_temp_sensor(1);
  const auto rd = rig.tick(0).readings[0];
  EXPECT_TRUE(rd.status_flags & c::kFlagTempSensorFault);
  ASSERT_EQ(rd.temps_c.size(), 3u);
  EXPECT_TRUE(std::isnan(rd.temps_c[1]));
  EXPECT_FALSE(std::isnan(rd.temps_c[0]));
}

// A board that announces TEMPS but never sends it: the latch still counts, temps are flagged.
TEST(CounterBoards, MissingAnnouncedTempsIsFlaggedNotLost) {
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv), 0);
  c::CounterBoardsConfig cfg{{{4, "RLG-4", 2.0}}, 50ms, 1.0};
  c::CounterBoards driver(can::make_fd_transport(UniqueFd(sv[0])), cfg);
  auto board = can::make_fd_transport(UniqueFd(sv[1]));
  const std::uint8_t follows = c::kFollowsCounts | c::kFollowsTemps;
  auto answer = [&](std::uint8_t seq, std::uint32_t up, std::uint32_t down, std::uint32_t t_us) {
    ASSERT_TRUE(driver.send_sync(seq).ok());
    ASSERT_TRUE(board->receive(1000ms).ok());
    ASSERT_TRUE(board->send(c::encode(c::StatusFrame{4, seq, 0, t_us, follows})).ok());
    ASSERT_TRUE(board->send(c::encode(c::CountsFrame{4, up, down})).ok());
  };
  answer(0, 100, 50, 5'000'000);
  ASSERT_TRUE(driver.collect(50ms).ok());
  answer(1, 1100, 60, 6'000'000);
  const auto r = driver.collect(50ms);
  ASSERT_TRUE(r.ok());
  const auto& rd = r.value().readings[0];
  EXPECT_TRUE(rd.answered);
  EXPECT_TRUE(rd.temps_missing);
  EXPECT_FALSE(rd.discharge_missing);
  EXPECT_EQ(rd.net_pulses, 990);
  EXPECT_DOUBLE_EQ(rd.angle_arcsec, 1980.0);
  EXPECT_TRUE(rd.interval_from_board_time);
  EXPECT_DOUBLE_EQ(rd.rate_dph, 1980.0);
}

// Board time is u32 µs and wraps every 4294.97 s; the interval must survive the wrap.
TEST(CounterBoards, BoardTimeWrapGivesTheTrueInterval) {
  auto b = board_config(2, 123);
  b.board_time_offset_us = 0xFFFFFFFFu - 1'500'000;
  Rig rig({b});
  for (std::uint8_t k = 0; k < 4; ++k) {
    const auto rd = rig.tick(k).readings[0];
    if (k == 0) continue;
    EXPECT_TRUE(rd.interval_from_board_time);
    EXPECT_NEAR(rd.interval_s, 1.0, 1e-9);
  }
}

TEST(CounterBoards, BackgroundThreadMode) {
  Rig rig({board_config(1, 5), board_config(7, 6)});
  rig.bus->start();
  for (int k = 0; k < 5; ++k) {
    rig.bus->step_to(k + 1.0, 25.0);
    auto r = rig.driver->tick(static_cast<std::uint8_t>(k));
    ASSERT_TRUE(r.ok()) << r.error().message;
    for (const auto& rd : r.value().readings) EXPECT_TRUE(rd.answered) << int(rd.node);
  }
  rig.bus->stop();
}

namespace {

// Fills the driver's send queue (nobody reads the other end) with frames the simulated boards
// ignore, so the next SYNC send times out for real. Returns the frames queued.
int jam_driver_tx(int fd) {
  const can_frame junk = c::encode(c::CountsFrame{9, 0, 0});  // not a SYNC: the boards skip it
  int n = 0;
  while (n < 1'000'000 && ::send(fd, &junk, sizeof junk, MSG_NOSIGNAL | MSG_DONTWAIT) > 0) ++n;
  return n;
}

// True mean rate over the last `span_s` seconds from the simulator's true angle, deg/h.
struct TrueRate {
  const sim::RlgGyroModel& gyro;
  double angle0 = gyro.true_angle_arcsec();
  double since(double span_s) const { return (gyro.true_angle_arcsec() - angle0) / span_s; }
};

}  // namespace

// A SYNC that could not be sent is still a tick that passed: the next good latch spans two
// intervals. Counted wrongly, the 2 s board time looks implausible against a 1 s nominal span,
// the nominal 1 s is used and the rate doubles. Bound: pulse angle within one pulse weight w of
// the true angle, so |rate - true mean rate| < w / interval_s.
TEST(CounterBoards, FailedSyncSendCountsItsInterval) {
  Rig rig({board_config(1, 202)});
  rig.tick(0);
  TrueRate truth{rig.bus->board(1).gyro()};
  rig.t_s += 1.0;
  rig.bus->step_to(rig.t_s, 25.0);
  ASSERT_GT(jam_driver_tx(rig.driver_side.get()), 0);
  auto sent = rig.driver->send_sync(1);
  ASSERT_FALSE(sent.ok());
  EXPECT_EQ(sent.error().kind, ErrorKind::timeout) << sent.error().message;
  EXPECT_EQ(rig.bus->service(1000ms), 0);  // drains the junk; no SYNC reached the boards
  const auto rd = rig.tick(2).readings[0];
  ASSERT_TRUE(rd.has_delta);
  EXPECT_EQ(rd.intervals_spanned, 2);
  EXPECT_TRUE(rd.interval_from_board_time);
  EXPECT_NEAR(rd.interval_s, 2.0, 1e-9);
  EXPECT_LT(std::abs(rd.rate_dph - truth.since(2.0)), kPulseWeightArcsec / 2.0);
}

// The sequencer skips ticks on overrun and says so; the next delta spans the skipped time.
TEST(CounterBoards, SkippedTicksAreCountedInTheSpan) {
  Rig rig({board_config(1, 303), board_config(2, 404)});
  rig.tick(0);
  TrueRate truth{rig.bus->board(2).gyro()};
  rig.t_s += 2.0;  // two ticks without a SYNC
  rig.driver->note_skipped_ticks(2);
  rig.driver->note_skipped_ticks(0);  // no-ops
  rig.driver->note_skipped_ticks(-1);
  const auto r = rig.tick(3);
  for (const auto& rd : r.readings) {
    ASSERT_TRUE(rd.has_delta);
    EXPECT_EQ(rd.intervals_spanned, 3);
    EXPECT_TRUE(rd.interval_from_board_time);
    EXPECT_NEAR(rd.interval_s, 3.0, 1e-9);
  }
  EXPECT_LT(std::abs(r.readings[1].rate_dph - truth.since(3.0)), kPulseWeightArcsec / 3.0);
  const auto next = rig.tick(4).readings[0];  // the span resets after a good latch
  EXPECT_EQ(next.intervals_spanned, 1);
}

// A late STATUS of an older latch, arriving after the current STATUS, must not withdraw the
// attribution: the current COUNTS that follow still belong to the current latch.
TEST(CounterBoards, LateStaleStatusDoesNotDiscardCurrentCounts) {
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv), 0);
  c::CounterBoardsConfig cfg{{{4, "RLG-4", 1.5}}, 50ms, 1.0};
  c::CounterBoards driver(can::make_fd_transport(UniqueFd(sv[0])), cfg);
  auto board = can::make_fd_transport(UniqueFd(sv[1]));
  auto status = [&](std::uint8_t seq, std::uint32_t t_us) {
    ASSERT_TRUE(board->send(c::encode(c::StatusFrame{4, seq, 0, t_us, c::kFollowsCounts})).ok());
  };
  ASSERT_TRUE(driver.send_sync(0).ok());
  ASSERT_TRUE(board->receive(1000ms).ok());
  status(0, 5'000'000);
  ASSERT_TRUE(board->send(c::encode(c::CountsFrame{4, 100, 50})).ok());
  ASSERT_TRUE(driver.collect(50ms).ok());
  ASSERT_TRUE(driver.send_sync(1).ok());
  ASSERT_TRUE(board->receive(1000ms).ok());
  status(1, 6'000'000);
  status(0, 5'000'000);  // late copy of the previous latch's STATUS
  ASSERT_TRUE(board->send(c::encode(c::CountsFrame{4, 1100, 60})).ok());
  const auto r = driver.collect(50ms);
  ASSERT_TRUE(r.ok());
  const auto& rd = r.value().readings[0];
  EXPECT_TRUE(rd.answered);
  EXPECT_FALSE(rd.latch_lost);
  EXPECT_EQ(rd.stale_frames, 1);
  EXPECT_EQ(rd.duplicate_frames, 0);
  EXPECT_EQ(rd.net_pulses, 990);
  EXPECT_EQ(rd.intervals_spanned, 1);
  EXPECT_TRUE(rd.interval_from_board_time);
  EXPECT_DOUBLE_EQ(rd.rate_dph, 1485.0);  // 990 pulses * 1.5 arcsec over 1 s
}

// A stale STATUS *before* the current one still makes its followers stale.
TEST(CounterBoards, StaleStatusBeforeCurrentKeepsFollowersStale) {
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv), 0);
  c::CounterBoardsConfig cfg{{{4, "RLG-4", 1.5}}, 50ms, 1.0};
  c::CounterBoards driver(can::make_fd_transport(UniqueFd(sv[0])), cfg);
  auto board = can::make_fd_transport(UniqueFd(sv[1]));
  ASSERT_TRUE(driver.send_sync(7).ok());
  ASSERT_TRUE(board->receive(1000ms).ok());
  ASSERT_TRUE(board->send(c::encode(c::StatusFrame{4, 6, 0, 1, c::kFollowsCounts})).ok());
  ASSERT_TRUE(board->send(c::encode(c::CountsFrame{4, 1, 1})).ok());
  ASSERT_TRUE(board->send(c::encode(c::StatusFrame{4, 7, 0, 2, c::kFollowsCounts})).ok());
  ASSERT_TRUE(board->send(c::encode(c::CountsFrame{4, 2, 2})).ok());
  const auto r = driver.collect(50ms);
  ASSERT_TRUE(r.ok());
  const auto& rd = r.value().readings[0];
  EXPECT_TRUE(rd.answered);
  EXPECT_EQ(rd.stale_frames, 2);
  EXPECT_EQ(rd.board_time_us, 2u);
}

// Fault setters race the bus thread unless they are atomic (run under TSan to see it).
TEST(CounterBoards, FaultInjectionWhileTheBusThreadRuns) {
  Rig rig({board_config(1, 505)});
  rig.bus->start();
  auto& b = rig.bus->board(1);
  for (int k = 0; k < 20; ++k) {
    b.set_extra_flags(k % 2 ? c::kFlagDitherFault : 0);
    b.fail_temp_sensor(2, k % 3 == 0);
    b.duplicate_next_frames(k % 2);
    b.set_answering(k % 5 != 4);
    rig.bus->step_to(k + 1.0, 25.0);
    auto r = rig.driver->tick(static_cast<std::uint8_t>(k));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r.value().readings[0].answered, k % 5 != 4) << k;
  }
  rig.bus->stop();
}
