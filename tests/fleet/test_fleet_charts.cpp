// The fleet's control charts from calibrations (no server needed: fleet_charts_json is pure).
// A station whose gyros drift away from the others shows as points beyond the fleet's limits.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "compensation/control_chart.hpp"
#include "station/fleet/fleet_charts.hpp"

namespace {

using station::fleet::FleetPoint;

std::vector<FleetPoint> line_of_two_stations(double rig_b_shift_dph_per_c) {
  std::vector<FleetPoint> pts;
  for (int i = 0; i < 40; ++i) {
    FleetPoint p;
    p.fleet_id = i + 1;
    p.station = i < 30 ? "rig-a" : "rig-b";  // rig-b calibrates the last ten
    p.serial = "RLG-" + std::to_string(i);
    p.created_utc = "2026-11-" + std::to_string(10 + i / 4) + "T00:00:00Z";
    p.part = "RLG-90";
    // A deterministic ±1e-4 scatter; rig-b's gyros shifted.
    const double scatter = 1e-4 * std::sin(1.7 * i);
    p.k1 = 0.01 + scatter + (i >= 30 ? rig_b_shift_dph_per_c : 0);
    p.k0 = 0.02 + scatter;
    p.b0 = 0.5;
    p.std_ratio = 0.2;
    p.pass = i % 7 != 0;
    pts.push_back(p);
  }
  return pts;
}

TEST(FleetCharts, AStationThatDriftsAwayShowsBeyondTheLimits) {
  const auto j = station::fleet::fleet_charts_json(line_of_two_stations(2e-3));
  ASSERT_EQ(j["parts"].size(), 1u);
  const auto& part = j["parts"][0];
  EXPECT_EQ(part["calibrations"], 40);
  int k1_above_b = 0, k1_station_b = 0, k0_out = 0;
  for (const auto& o : part["outside"]) {
    const bool b = o["metric"] == "k1" && o["station"] == "rig-b";
    if (b && o["chart"] == "overall" && o["limit"] == "UCL") ++k1_above_b;
    if (b && o["chart"] == "station") ++k1_station_b;
    if (o["metric"] == "k0") ++k0_out;
  }
  // The shift is 20x the scatter: every rig-b point is above the fleet's UCL, while within its
  // own chart rig-b is in control; k0, not shifted, shows nothing.
  EXPECT_EQ(k1_above_b, 10);
  EXPECT_EQ(k1_station_b, 0);
  EXPECT_EQ(k0_out, 0);
  // Verdicts per station: i % 7 == 0 fail (i = 0, 7, ..., 28 at rig-a; 35 at rig-b).
  EXPECT_EQ(part["verdicts"]["rig-a"]["fail"], 5);
  EXPECT_EQ(part["verdicts"]["rig-b"]["fail"], 1);
  EXPECT_EQ(part["charts"][0]["unit"], "deg/h/C");
  EXPECT_EQ(part["charts"][3]["unit"], "1");
  // Each station's own chart is centred on its own gyros.
  EXPECT_NEAR(part["charts"][0]["by_station"]["rig-b"]["centre"].get<double>(), 0.012, 1e-4);
}

TEST(FleetCharts, WithoutADriftNothingIsFlagged) {
  const auto j = station::fleet::fleet_charts_json(line_of_two_stations(0));
  EXPECT_TRUE(j["parts"][0]["outside"].empty()) << j["parts"][0]["outside"].dump();
}

// Stations calibrating in turn (rig-b every fourth gyro): the moving ranges of the overall chart
// are taken within each station, so rig-b's offset does not widen the limits it must break.
TEST(FleetCharts, AnOffsetStationInterleavedInTimeStillShows) {
  auto pts = line_of_two_stations(0);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    pts[i].station = i % 4 == 3 ? "rig-b" : "rig-a";
    if (pts[i].station == "rig-b") *pts[i].k1 += 2e-3;
  }
  const auto j = station::fleet::fleet_charts_json(pts);
  int above = 0;
  for (const auto& o : j["parts"][0]["outside"])
    if (o["metric"] == "k1" && o["station"] == "rig-b" && o["limit"] == "UCL") ++above;
  EXPECT_EQ(above, 10);
  // Without the groups (one sequence), the ranges across stations swallow the offset.
  std::vector<double> k1;
  for (const auto& p : pts) k1.push_back(*p.k1);
  const auto pooled = station::compensation::individuals_chart(k1);
  ASSERT_TRUE(pooled.has_value());
  EXPECT_TRUE(pooled->outside.empty());
}

TEST(FleetCharts, ModelsAndReferenceTemperaturesAreChartedApart) {
  auto pts = line_of_two_stations(0);
  for (std::size_t i = 0; i < pts.size(); i += 2) pts[i].ref_temp_c = 20;
  const auto j = station::fleet::fleet_charts_json(pts);
  ASSERT_EQ(j["parts"].size(), 2u);
  EXPECT_EQ(j["parts"][0]["calibrations"].get<int>() + j["parts"][1]["calibrations"].get<int>(),
            40);
}

// Issue 35: `station fleet` printed "part (no part): ..." twice, the model that separates the two
// chart sets unnamed. Each set's title names part, model and T_ref, and no two are alike.
TEST(FleetCharts, EachChartSetIsNamedByPartModelAndReference) {
  auto pts = line_of_two_stations(0);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    pts[i].part = station::fleet::kNoPart;
    pts[i].terms = i % 2 == 0 ? "B0+dT+gradT" : "B0+dT";
    pts[i].ref_temp_c = i < 4 ? 20 : 25;
  }
  const auto j = station::fleet::fleet_charts_json(pts);
  ASSERT_EQ(j["parts"].size(), 4u);
  std::set<std::string> titles;
  for (const auto& part : j["parts"]) titles.insert(station::fleet::chart_set_title(part));
  EXPECT_EQ(titles, (std::set<std::string>{"part (no part), model B0+dT, T_ref 20 C",
                                           "part (no part), model B0+dT, T_ref 25 C",
                                           "part (no part), model B0+dT+gradT, T_ref 20 C",
                                           "part (no part), model B0+dT+gradT, T_ref 25 C"}));
}

}  // namespace
