// The live hub's numbers: live bins equal the stored bins' arithmetic (calibration.cpp's filter,
// bias = mean rate − Earth rate), the trend stays within 2000 points, a slow stream reader is
// told to resync, ticks are rate-limited but bins and events never are.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "station/live/live_bins.hpp"
#include "station/live/live_hub.hpp"
#include "station/store/calibration.hpp"

namespace station::live {
namespace {

/// A gyro's 1 Hz samples over `n` s of record window, seeded: rate, two temperatures.
std::vector<SampleRow> record(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.3);
  std::vector<SampleRow> rows;
  for (int i = 0; i < n; ++i) {
    SampleRow r;
    r.serial = "SN1";
    r.t_s = 1000.0 + i;
    r.recording = true;
    r.temp_c = -40.0 + 0.003 * i;
    r.temp2_c = *r.temp_c + 0.5;
    r.rate_dph = 9.7 + 0.01 * *r.temp_c + noise(rng);
    if (i % 97 == 0) r.flags = kSafeHold;  // left out, as in the stored bins
    rows.push_back(r);
  }
  return rows;
}

TEST(LiveBins, EqualTheStoredBinsArithmetic) {
  const double earth_dph = 9.66;
  const auto rows = record(3600, 7);
  LiveBins live({{"SN1", earth_dph}}, 600.0);
  std::vector<LiveBin> got;
  for (const auto& r : rows)
    for (const auto& [serial, b] : live.add({r})) got.push_back(b);
  const auto stored = bin_samples(rows, 600.0);  // what the run's end stores
  // Six windows from the first usable sample (t = 1001: the one at 1000 is in safe hold); the
  // sixth is still open live and dropped when stored (the record does not reach its end).
  ASSERT_EQ(got.size(), 5u);
  ASSERT_EQ(stored.size(), 5u);
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k].n, static_cast<int>(stored[k].n)) << k;
    // Same sums in the same order up to the bias subtraction: agreement to rounding, 1e-12.
    EXPECT_NEAR(got[k].bias_dph, stored[k].rate_dph - earth_dph, 1e-12) << k;
    EXPECT_NEAR(got[k].temp_c, stored[k].temp_c, 1e-12) << k;
    EXPECT_NEAR(got[k].grad_c, stored[k].grad_c, 1e-12) << k;
    EXPECT_NEAR(got[k].t_mid_s, stored[k].t_mid_s, 1e-9) << k;
    EXPECT_EQ(got[k].complete, stored[k].complete) << k;
  }
}

TickReport tick_at(double t_s, std::int64_t run_id) {
  TickReport r;
  r.t_s = t_s;
  r.run_id = run_id;
  r.chamber = drivers::ChamberState{};
  r.chamber->air_c = 20.0 - t_s / 1000.0;
  r.chamber->setpoint_c = 20.0;
  return r;
}

TEST(LiveHub, TrendStaysWithin2000PointsOverA13HourRun) {
  LiveHub hub({"test", true, std::nullopt, 600.0});
  Protocol p;
  p.name = "paper";
  hub.run_started(1, p, "ann", {});
  const int ticks = 13 * 3600;
  for (int t = 0; t < ticks; ++t) hub.tick(tick_at(t, 1));
  const auto live = hub.live();
  const auto& trend = live["trend"];
  EXPECT_LT(trend.size(), 2000u);
  EXPECT_GT(trend.size(), 1000u);  // halving keeps at least half the cap
  EXPECT_EQ(trend.front()[0].get<double>(), 0.0);
  // Evenly thinned: one stride between consecutive points.
  const double step = trend[1][0].get<double>() - trend[0][0].get<double>();
  for (std::size_t i = 1; i < trend.size(); ++i)
    ASSERT_EQ(trend[i][0].get<double>() - trend[i - 1][0].get<double>(), step) << i;
  EXPECT_EQ(live["status"]["state"], "running");
  EXPECT_EQ(live["status"]["ticks"], ticks);
}

TEST(LiveHub, ASlowReaderIsToldToResyncAndEventsAreNeverDropped) {
  LiveHub hub({"test", true, std::nullopt, 600.0});
  Protocol p;
  hub.run_started(1, p, "", {});
  const auto start = hub.last_id();
  // 600 events: more than the 512 the stream keeps.
  for (int i = 0; i < 600; ++i)
    hub.event({i + 1, 1, double(i), station::Severity::info, "seq", station::EventKind::done, "m"});
  std::vector<StreamMessage> out;
  ASSERT_TRUE(hub.wait(start, out, std::chrono::milliseconds(0)));
  ASSERT_FALSE(out.empty());
  EXPECT_NE(out.front().text.find("event: resync"), std::string::npos);
  EXPECT_EQ(out.size(), 513u);  // resync + the 512 kept
  // A reader that keeps up sees every event: ticks are rate-limited, events are not.
  out.clear();
  const auto now = hub.last_id();
  for (int i = 0; i < 50; ++i) hub.tick(tick_at(1000 + i, 1));
  hub.event({700,
             1,
             1050,
             station::Severity::warn,
             "chamber",
             station::EventKind::outage_start,
             "not answering",
             {{"device", "chamber"}, {"error", "timeout"}}});
  ASSERT_TRUE(hub.wait(now, out, std::chrono::milliseconds(0)));
  int ticks = 0, events = 0;
  for (const auto& m : out) {
    ticks += m.text.find("event: tick") != std::string::npos;
    events += m.text.find("event: event") != std::string::npos;
  }
  EXPECT_EQ(events, 1);
  EXPECT_LT(ticks, 50);  // 50 ticks in well under 100 ms: at most one or two messages
  hub.close();
  EXPECT_FALSE(hub.wait(hub.last_id(), out, std::chrono::milliseconds(1000)));
}

TEST(LiveHub, StateFollowsRunHoldAndFault) {
  LiveHub hub({"test", false, std::nullopt, 600.0});
  EXPECT_EQ(hub.status()["state"], "idle");
  IdleReading idle;
  idle.fault = "chamber: timeout";
  hub.idle(idle);
  EXPECT_EQ(hub.status()["state"], "fault");
  EXPECT_EQ(hub.status()["fault"], "chamber: timeout");
  Protocol p;
  hub.run_started(4, p, "", {});
  auto r = tick_at(0, 4);
  r.safe_hold = true;
  hub.tick(r);
  EXPECT_EQ(hub.status()["state"], "hold");
  EXPECT_EQ(hub.current_run(), 4);
  hub.run_ended(4, "stopped");
  EXPECT_EQ(hub.status()["state"], "fault");  // the last idle look still said so
  hub.idle(IdleReading{});                    // the next one is clear
  EXPECT_EQ(hub.status()["state"], "idle");
  hub.run_started(5, p, "", {});
  hub.run_ended(5, "failed: disk full");  // a failed run is a fault until the next run starts
  hub.idle(IdleReading{});
  EXPECT_EQ(hub.status()["state"], "fault");
  EXPECT_EQ(hub.status()["fault"], "failed: disk full");
  hub.run_started(6, p, "", {});
  hub.run_ended(6, "stopped");
  EXPECT_EQ(hub.status()["last_run_id"], 6);
  EXPECT_FALSE(hub.current_run());
  const auto metrics = hub.metrics().text();
  EXPECT_NE(metrics.find("station_run_state{state=\"idle\"} 1"), std::string::npos);
  EXPECT_NE(metrics.find("station_run_id 6"), std::string::npos);
}

}  // namespace
}  // namespace station::live
