// When may a latch's counts be subtracted from the previous good latch's? Only when the board
// provably kept counting. A board reset must be reported, never read as a ~2^32 delta; a gap the
// board clock cannot vouch for is re-baselined; a replayed log gives the same latches however
// slow the machine replaying it.
#include <gtest/gtest.h>
#include <sys/socket.h>

#include <cmath>
#include <thread>

#include "drivers/counters/counter_boards.hpp"
#include "drivers/counters/counter_frames.hpp"
#include "station/session/replay_can.hpp"

using namespace station::drivers;
using namespace std::chrono_literals;
namespace c = station::drivers::counters;

namespace {

// A driver for one board (node 4, 1.5 arcsec) and a hand-driven board on a socketpair.
struct OneBoard {
  std::unique_ptr<c::CounterBoards> driver;
  std::unique_ptr<can::CanTransport> board;
  OneBoard() {
    int sv[2];
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0) throw std::exception();
    c::CounterBoardsConfig cfg{{{4, "RLG-4", 1.5}}, 50ms, 1.0};
    driver = std::make_unique<c::CounterBoards>(can::make_fd_transport(UniqueFd(sv[0])), cfg);
    board = can::make_fd_transport(UniqueFd(sv[1]));
  }
  // One latch answered with these counts, board clock and flags.
  c::CounterReading latch(std::uint8_t seq, std::uint32_t up, std::uint32_t down,
                          std::uint32_t t_us, std::uint8_t flags = 0) {
    EXPECT_TRUE(driver->send_sync(seq));
    EXPECT_TRUE(board->receive(1000ms));
    EXPECT_TRUE(board->send(c::encode(c::StatusFrame{4, seq, flags, t_us, c::kFollowsCounts})));
    EXPECT_TRUE(board->send(c::encode(c::CountsFrame{4, up, down})));
    auto r = driver->collect(1000ms);
    EXPECT_TRUE(r.ok());
    return r.value().readings.at(0);
  }
  // A latch nobody answers (the link is down).
  void lost(std::uint8_t seq) {
    EXPECT_TRUE(driver->send_sync(seq));
    EXPECT_TRUE(board->receive(1000ms));
    EXPECT_TRUE(driver->collect(1ms).ok());
  }
};

}  // namespace

// Board restarted (simrig restarted, power cycle): counts and clock start again near zero. The
// old code took 10 - 1100 mod 2^32 as pulses over the nominal interval: ~6e9 deg/h.
TEST(CounterChain, BoardResetIsReportedNotReadAsAHugeDelta) {
  OneBoard b;
  b.latch(0, 1000, 500, 5'000'000);
  const auto ok = b.latch(1, 1100, 600, 6'000'000);
  EXPECT_EQ(ok.chain, c::LatchChain::continuous);
  b.lost(2);
  const auto reset = b.latch(3, 10, 5, 200'000);
  EXPECT_EQ(reset.chain, c::LatchChain::reset);
  EXPECT_FALSE(reset.has_delta);
  EXPECT_EQ(reset.net_pulses, 0);
  EXPECT_EQ(reset.rate_dph, 0.0);
  const auto next = b.latch(4, 2010, 5, 1'200'000);  // counting from the new baseline
  EXPECT_EQ(next.chain, c::LatchChain::continuous);
  EXPECT_EQ(next.net_pulses, 2000);
  EXPECT_DOUBLE_EQ(next.rate_dph, 3000.0);  // 2000 * 1.5 arcsec over 1 s of board clock
}

// Counters restarted but the board clock did not (and no flag said so): still a reset.
TEST(CounterChain, CountsGoingBackwardsAreAReset) {
  OneBoard b;
  b.latch(0, 1'000'000, 999'000, 5'000'000);
  const auto r = b.latch(1, 100, 50, 6'000'000);
  EXPECT_EQ(r.chain, c::LatchChain::reset);
  EXPECT_FALSE(r.has_delta);
}

TEST(CounterChain, CounterResetFlagIsAReset) {
  OneBoard b;
  b.latch(0, 1000, 500, 5'000'000);
  const auto r = b.latch(1, 1100, 600, 6'000'000, c::kFlagCounterReset);
  EXPECT_EQ(r.chain, c::LatchChain::reset);
  EXPECT_FALSE(r.has_delta);
}

// After 3 lost latches the board clock says 40 s passed instead of ~4 s: the counts cannot be
// trusted to span the gap (nor the clock to time it), so no delta. The old code fell back to the
// nominal 4 s and stored a rate 10 times too high.
TEST(CounterChain, GapTheBoardClockDisagreesWithIsRebaselined) {
  OneBoard b;
  b.latch(0, 1000, 500, 5'000'000);
  for (std::uint8_t k = 1; k <= 3; ++k) b.lost(k);
  const auto r = b.latch(4, 41'000, 500, 45'000'000);
  EXPECT_EQ(r.chain, c::LatchChain::unproven);
  EXPECT_FALSE(r.has_delta);
  const auto next = b.latch(5, 42'000, 500, 46'000'000);
  EXPECT_EQ(next.chain, c::LatchChain::continuous);
  EXPECT_EQ(next.intervals_spanned, 1);
}

// Continuity proven across lost latches: the delta spans the gap, timed by the board clock.
TEST(CounterChain, GapTheBoardClockVouchesForKeepsItsDelta) {
  OneBoard b;
  b.latch(0, 1000, 500, 5'000'000);
  for (std::uint8_t k = 1; k <= 9; ++k) b.lost(k);
  const auto r = b.latch(10, 1000 + 15'000, 500, 15'000'000);
  EXPECT_EQ(r.chain, c::LatchChain::continuous);
  EXPECT_EQ(r.intervals_spanned, 10);
  EXPECT_DOUBLE_EQ(r.interval_s, 10.0);
  EXPECT_DOUBLE_EQ(r.rate_dph, 15'000 * 1.5 / 10.0);
}

TEST(CounterChain, ForgetLatchesStartsANewBaseline) {
  OneBoard b;
  b.latch(0, 1000, 500, 5'000'000);
  b.driver->forget_latches();
  const auto r = b.latch(1, 1100, 600, 9'000'000);
  EXPECT_EQ(r.chain, c::LatchChain::first);
  EXPECT_FALSE(r.has_delta);
}

namespace {

// A transport that stalls before every receive, as a loaded machine (or ASan) does.
class Stalling final : public can::CanTransport {
 public:
  Stalling(std::unique_ptr<can::CanTransport> inner, std::chrono::milliseconds stall)
      : inner_(std::move(inner)), stall_(stall) {}
  Result<void> send(const can_frame& f) override { return inner_->send(f); }
  Result<can_frame> receive(std::chrono::milliseconds timeout) override {
    std::this_thread::sleep_for(stall_);
    return inner_->receive(timeout);
  }
  int fd() const override { return inner_->fd(); }
  double last_rx_time_s() const override { return inner_->last_rx_time_s(); }

 private:
  std::unique_ptr<can::CanTransport> inner_;
  std::chrono::milliseconds stall_;
};

// A log of `n` latches of boards 1 and 2 (STATUS, COUNTS, TEMPS each), 1 s apart.
std::vector<can::CandumpRecord> latch_log(int n) {
  std::vector<can::CandumpRecord> log;
  auto add = [&](int k, const can_frame& f) {
    log.push_back({1'700'000'000 + k, static_cast<std::uint32_t>(k % 1000), "can0", f});
  };
  for (int k = 0; k < n; ++k) {
    const auto seq = static_cast<std::uint8_t>(k);
    add(k, c::encode(c::SyncFrame{seq}));
    for (std::uint8_t node = 1; node <= 2; ++node) {
      const auto t_us = static_cast<std::uint32_t>(k * 1'000'000 + node);
      const auto up = static_cast<std::uint32_t>(20'000 * k + 7 * k * k + node);
      add(k, c::encode(c::StatusFrame{node, seq, 0, t_us, c::kFollowsCounts | c::kFollowsTemps}));
      add(k, c::encode(c::CountsFrame{node, up, static_cast<std::uint32_t>(20'000 * k)}));
      add(k, c::encode(c::TempsFrame{node, 2, {2500, 2510}}));
    }
  }
  return log;
}

// Rates of every latch replayed through the driver, configured as `station replay` does.
std::vector<double> replay_rates(std::chrono::milliseconds stall) {
  auto log = latch_log(8);
  const auto syncs = station::logged_syncs(log);
  c::CounterBoardsConfig cfg{{{1, "A", 1.5}, {2, "B", 1.5}}, 1ms, 1.0};
  cfg.wall_clock_deadline = false;  // what replay_command sets
  c::CounterBoards boards(std::make_unique<Stalling>(
                              std::make_unique<station::ReplayCanTransport>(std::move(log)), stall),
                          cfg);
  std::vector<double> rates;
  for (const auto seq : syncs) {
    auto t = boards.tick(seq);
    EXPECT_TRUE(t.ok());
    for (const auto& r : t.value().readings) rates.push_back(r.has_delta ? r.rate_dph : NAN);
  }
  return rates;
}

}  // namespace

// With the 1 ms wall-clock deadline replay used to have, a 3 ms stall per frame lost every latch
// after its first frame and the fit "DIFFERED". Replay must hand out the log's frames whatever
// the wall clock does.
TEST(CounterChain, ReplayedLogIsTheSameOnAStalledMachine) {
  const auto fast = replay_rates(0ms);
  const auto stalled = replay_rates(3ms);
  ASSERT_EQ(fast.size(), 16u);
  EXPECT_TRUE(std::isnan(fast[0]) && std::isnan(fast[1]));  // the first latch is the baseline
  for (std::size_t i = 2; i < fast.size(); ++i) {
    EXPECT_FALSE(std::isnan(fast[i])) << i;
    EXPECT_EQ(fast[i], stalled[i]) << i;
  }
}
