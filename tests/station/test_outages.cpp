// OutageTracker and record-window loss: pure bookkeeping, no rig.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "station/config/config.hpp"
#include "station/daemon/outages.hpp"

using station::Outage;
using station::OutageChange;
using station::OutageTracker;

TEST(Outages, OneStartAndOneEndPerOutageWithTheTicksItCost) {
  OutageTracker t;
  EXPECT_FALSE(t.observe("chamber", 0, true));
  const auto start = t.observe("chamber", 1, false, "connect refused");
  ASSERT_TRUE(start);
  EXPECT_EQ(start->change, OutageChange::started);
  EXPECT_EQ(start->outage.error, "connect refused");
  for (double s = 2; s <= 4; ++s) EXPECT_FALSE(t.observe("chamber", s, false, "again")) << s;
  EXPECT_TRUE(t.down("chamber"));
  const auto end = t.observe("chamber", 5, true);
  ASSERT_TRUE(end);
  EXPECT_EQ(end->change, OutageChange::ended);
  EXPECT_EQ(end->outage.start_s, 1);
  EXPECT_EQ(end->outage.end_s, 5);
  EXPECT_EQ(end->outage.ticks_lost, 4);
  EXPECT_TRUE(end->outage.recovered);
  EXPECT_EQ(end->outage.error, "connect refused");  // the first lost tick's reason
  EXPECT_FALSE(t.down("chamber"));
  const auto j = station::outage_json(end->outage, station::OutageEnd::answered);
  EXPECT_EQ(j, (nlohmann::json{{"device", "chamber"},
                               {"start_s", 1.0},
                               {"end_s", 5.0},
                               {"ticks_lost", 4},
                               {"ended", "answered"}}));
  EXPECT_EQ(station::outage_json(end->outage, station::OutageEnd::abort)["ended"], "abort");
}

// A board behind a lost bus has no news: nothing starts; an outage it was already in goes on
// counting and does not end.
TEST(Outages, NoNewsNeitherStartsNorEndsButCounts) {
  OutageTracker t;
  EXPECT_FALSE(t.observe("can node 1", 0, std::nullopt));
  EXPECT_FALSE(t.down("can node 1"));
  ASSERT_TRUE(t.observe("can node 2", 1, false));
  EXPECT_FALSE(t.observe("can node 2", 2, std::nullopt));
  const auto end = t.observe("can node 2", 3, true);
  ASSERT_TRUE(end);
  EXPECT_EQ(end->outage.ticks_lost, 2);
}

TEST(Outages, OpenOutagesCloseAtTheRunsEnd) {
  OutageTracker t;
  ASSERT_TRUE(t.observe("can", 10, false, "peer closed"));
  ASSERT_TRUE(t.observe("turntable", 12, false, "timeout"));
  t.observe("can", 11, false);
  const auto open = t.close_all(20);
  ASSERT_EQ(open.size(), 2u);
  EXPECT_EQ(open[0].device, "can");
  EXPECT_EQ(open[0].end_s, 20);
  EXPECT_EQ(open[0].ticks_lost, 2);
  EXPECT_FALSE(open[0].recovered);
  EXPECT_TRUE(t.close_all(21).empty());
}

TEST(Outages, WindowLossCountsMissingRatesAndMissingTicks) {
  std::vector<station::SampleRow> rows;
  for (int t = 100; t < 200; ++t) {
    if (t >= 150 && t < 155) continue;  // daemon down: never stored
    station::SampleRow r;
    r.t_s = t;
    r.recording = true;
    if (t % 10 != 0) r.rate_dph = 1.0;  // multiples of 10: stored without a rate
    rows.push_back(r);
  }
  const auto w = station::record_window_loss(rows, 1.0);
  EXPECT_EQ(w.ticks, 100);
  EXPECT_EQ(w.lost, 5 + 9);  // 5 never stored, 9 multiples of 10 stored (150 was not)
  EXPECT_DOUBLE_EQ(w.share(), 0.14);
  EXPECT_EQ(station::record_window_loss({}, 1.0).share(), 0.0);
}

TEST(Outages, MaxLostShareIsConfiguredAndBounded) {
  const std::string rest =
      "[chamber]\nendpoint = \"tcp://127.0.0.1:502\"\n[can]\ntransport = \"fd:3\"\n"
      "[[slot]]\nnode = 1\nserial = \"G1\"\n";
  auto parse = [&](const std::string& station) {
    return station::parse_station_config("[station]\nlatitude_deg = 1\n" + station + rest,
                                         "s.toml");
  };
  EXPECT_DOUBLE_EQ(parse("").max_lost_share, 0.05);
  EXPECT_DOUBLE_EQ(parse("max_lost_share = 0.2\n").max_lost_share, 0.2);
  for (const char* bad :
       {"max_lost_share = 1.5\n", "max_lost_share = -0.1\n", "max_lost_share = nan\n"}) {
    try {
      parse(bad);
      ADD_FAILURE() << bad;
    } catch (const station::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("max_lost_share"), std::string::npos) << e.what();
    }
  }
}
