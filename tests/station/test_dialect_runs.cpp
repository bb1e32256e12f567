// Issue 20: a thermal cycle end to end on every chamber dialect x every table dialect, each
// device served by its dialect's simulator face on its real transport (Modbus TCP or ASCII
// lines over TCP), and the fitted coefficients within 5 standard errors of the simulator's truth.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "sim_devices/fault_commands.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/store.hpp"
#include "tests/station/sim_options.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using Combo = std::tuple<std::string, std::string>;

class DialectRun : public ::testing::TestWithParam<Combo> {};

// 5 SE: a two-sided normal tail of 6e-7 per coefficient, so 24 comparisons never fail by chance;
// a dialect that misreads temperatures by even a tenth of a degree shifts k1 by far more.
constexpr double kSe = 5.0;

TEST_P(DialectRun, ShortCycleCompletesAndFitsTheTruth) {
  const auto& [chamber, table] = GetParam();
  const auto db = station::testing_support::fresh_db("dialect_" + chamber + "_" + table);
  auto o = station::testing_support::short_cycle_run(db, 1);
  o.chamber_model = chamber;
  o.turntable_model = table;
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  const auto& g = r["gyros"].at(0);
  ASSERT_TRUE(g.contains("fitted")) << g.dump();
  for (const char* k : {"k1", "k0"}) {
    const double fit = g["fitted"][k].get<double>(), truth = g["true"][k].get<double>();
    const double se = g["std_errors"][k].get<double>();
    EXPECT_LT(std::abs(fit - truth), kSe * se) << chamber << "/" << table << " " << k;
  }
  // The config the run stored names the dialects it spoke.
  station::Store store(db);
  const auto run = store.find_run(r["run_id"].get<std::int64_t>());
  ASSERT_TRUE(run.has_value());
  const auto& text = run->config_text;
  EXPECT_NE(text.find("model = \"" + chamber + "\""), std::string::npos) << text;
  EXPECT_NE(text.find("model = \"" + table + "\""), std::string::npos) << text;
}

INSTANTIATE_TEST_SUITE_P(
    AllDialects, DialectRun,
    ::testing::Combine(::testing::Values("generic_plc", "watlow_f4", "watlow_f4t",
                                         "watlow_f4t_map2", "watlow_f4p", "espec_p300"),
                       ::testing::Values("generic_plc", "acutrol3000")),
    [](const auto& info) { return std::get<0>(info.param) + "_" + std::get<1>(info.param); });

// Link faults on the ASCII and float dialects: a stalled F4T, an ACUTROL that drops its
// connection, a P300 answering NA: for a while -- the run reports, retries and completes.
TEST(DialectFaults, RunsSurviveStallsDropsAndErrorReplies) {
  for (const auto& [chamber, table] :
       {Combo{"watlow_f4t", "acutrol3000"}, Combo{"espec_p300", "acutrol3000"}}) {
    const auto db = station::testing_support::fresh_db("dialect_faults_" + chamber);
    auto o = station::testing_support::short_cycle_run(db, 1);
    o.chamber_model = chamber;
    o.turntable_model = table;
    o.on_world_tick = [&](double t_s, station::sim::SimWorld& w) {
      const auto cmd = [&](const char* c) {
        EXPECT_EQ(station::sim::run_fault_command(w, c).rfind("ok", 0), 0u) << c;
      };
      if (t_s == 1500) cmd("chamber stall 2");
      if (t_s == 2000) cmd("table disconnect 1");
      if (t_s == 2300) cmd("chamber exception 4 5");  // 5 error replies (NA: on a P300)
    };
    const auto r = station::run_simulated(o);
    EXPECT_EQ(r["state"], "completed") << chamber << " " << r.dump();
  }
}

}  // namespace
