// Issue 35, "Examples that are true": every example file's comments say what it does, and each
// claim is checked here by doing it. station/parts/example_parts.toml: the ranges it gives of the
// simulated gyros and of their fits on the paper protocol, "every simulated gyro passes" GX-200,
// "most fail" GX-200-A. examples/station.toml: simrig on the ports it names serves it, probe
// reads every device. (examples/station_rtu.toml: Config.ExamplesLoad, its schema test;
// examples/thermal_cycle.csv: Cli.AnalyzeExampleRecoversTheGeneratorsCoefficients; the demo
// protocol: Readme.RigWalkthrough.)
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "tests/station/rig_process.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace ts = station::testing_support;
using namespace std::chrono_literals;

const std::string kSrc = STATION_SOURCE_DIR;
const std::string kParts = kSrc + "/station/parts/example_parts.toml";

// The paper protocol on 8 simulated gyros, seed 1, judged against `part`: the --json report.
nlohmann::json sim_run(const std::string& part, const std::string& db) {
  const auto o = ts::station_command("run --sim --gyros 8 --seed 1 --new --json --db " + db +
                                         " --parts " + kParts + " --part " + part,
                                     "example-parts-" + part);
  EXPECT_EQ(o.status, 0) << o.out;
  // stdout and stderr share the output: the JSON is the object that starts a line ("{").
  const auto at = o.out.compare(0, 2, "{\n") == 0 ? std::string::npos : o.out.find("\n{\n");
  return nlohmann::json::parse(at == std::string::npos ? o.out : o.out.substr(at + 1));
}

// The header's ranges of the fits (std after, deg/h; SE of k1 and k0, deg/h/C).
constexpr double kStdAfterLo = 0.006, kStdAfterHi = 0.010;
constexpr double kK1SeLo = 3e-5, kK1SeHi = 7e-5;
constexpr double kK0SeLo = 4e-3, kK0SeHi = 7e-3;

bool within(double v, double lo, double hi) {
  return v >= lo && v <= hi;
}

}  // namespace

// example_parts.toml's header: the simulated gyros (|B0| <= 0.1 deg/h, |k1| 2..5e-3 and |k0|
// 0.01..0.04 deg/h/C, docs/SIMRIG.md's table), their fits on the paper protocol (66 bins, the
// ranges below) and GX-200 "production grade: every simulated gyro passes".
TEST(ExampleFiles, PartsFileIsTrueOfTheSimulatedGyros) {
  const auto j = sim_run("GX-200", ts::fresh_db("example-parts"));
  ASSERT_EQ(j["gyros"].size(), 8u);
  for (const auto& g : j["gyros"]) {
    SCOPED_TRACE(g.dump());
    const auto& t = g["true"];
    EXPECT_LE(std::abs(t["B0"].get<double>()), 0.1);
    EXPECT_TRUE(within(std::abs(t["k1"].get<double>()), 2e-3, 5e-3));
    EXPECT_TRUE(within(std::abs(t["k0"].get<double>()), 0.01, 0.04));
    EXPECT_EQ(g["bins"].get<int>(), 66);
    EXPECT_TRUE(within(g["std_after_dph"].get<double>(), kStdAfterLo, kStdAfterHi));
    EXPECT_TRUE(within(g["std_errors"]["k1"].get<double>(), kK1SeLo, kK1SeHi));
    EXPECT_TRUE(within(g["std_errors"]["k0"].get<double>(), kK0SeLo, kK0SeHi));
    EXPECT_EQ(g["part_number"], "GX-200");
    EXPECT_EQ(g["verdict"]["pass"], true);
  }
}

// GX-200-A: "selected grade: ... (most simulated gyros fail)".
TEST(ExampleFiles, PartsFileSelectedGradeFailsMostSimulatedGyros) {
  const auto j = sim_run("GX-200-A", ts::fresh_db("example-parts-a"));
  int failed = 0;
  for (const auto& g : j["gyros"]) failed += g["verdict"]["pass"] == false ? 1 : 0;
  EXPECT_GT(failed, 4) << j.dump();
}

// examples/station.toml: "Start `simrig --chamber-port 15020 --turntable-port 15021` first ...
// then `station probe --config examples/station.toml` reads every device".
TEST(ExampleFiles, StationExampleIsServedBySimrigOnItsPorts) {
  ts::SimrigProcess rig;
  rig.extra_args = {"--chamber-port", "15020", "--turntable-port", "15021"};
  ASSERT_TRUE(rig.start("example-station")) << ts::slurp(rig.err);
  // The file as shipped; only the CAN socket is this test's (simrig --can-socket).
  std::ifstream in(kSrc + "/examples/station.toml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string shipped = "unix:/tmp/simrig-can.sock";
  ASSERT_NE(text.find(shipped), std::string::npos);
  text.replace(text.find(shipped), shipped.size(), "unix:" + rig.can_socket);
  const std::string config =
      ::testing::TempDir() + "example-station-" + std::to_string(getpid()) + ".toml";
  std::ofstream(config) << text;
  const auto o = ts::station_command("probe --config " + config, "example-station");
  EXPECT_EQ(o.status, 0) << o.out;
  EXPECT_NE(o.out.find("all devices answered"), std::string::npos) << o.out;
}
