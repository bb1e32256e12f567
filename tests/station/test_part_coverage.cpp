// Issue 35: `run --config ... --parts FILE` where a slot names no part judged it against nothing
// and said only "no part limits" at the end. The slots a part file does not judge are named when
// the run starts, before any device is touched.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <iterator>

#include "station/config/config.hpp"
#include "station/parts/part_coverage.hpp"
#include "tests/station/rig_process.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace ts = station::testing_support;

const std::string kExample = std::string(STATION_SOURCE_DIR) + "/examples/station.toml";
const std::string kParts = std::string(STATION_SOURCE_DIR) + "/station/parts/example_parts.toml";

std::string example_config(bool first_slot_has_part) {
  std::ifstream in(kExample);
  std::string config((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (first_slot_has_part) config.insert(config.find("axis = \"up\""), "part = \"GX-200\"\n");
  const std::string path = ::testing::TempDir() + "coverage-" + std::to_string(getpid()) +
                           (first_slot_has_part ? "-one" : "-none") + ".toml";
  std::ofstream(path) << config;
  return path;
}

bool has(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

}  // namespace

TEST(PartCoverage, EverySlotWithoutAPartIsNamedWhenAPartFileIsGiven) {
  const auto none = station::load_station_config(example_config(false));
  const auto lines = station::slots_without_part(none, kParts);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], kParts +
                          ": slot 1 (node 1, serial RLG-0001) names no part: no part limits, no "
                          "verdict (name one: --slot 1=RLG-0001,PART or [[slot]] part = \"PART\")");
  EXPECT_TRUE(has(lines[1], "slot 2 (node 2, serial RLG-0002)"));
  const auto one = station::load_station_config(example_config(true));
  ASSERT_EQ(station::slots_without_part(one, kParts).size(), 1u);
  EXPECT_TRUE(has(station::slots_without_part(one, kParts)[0], "slot 2 "));
  // No part file in effect: nothing to say (every gyro is judged against nothing, as asked).
  EXPECT_TRUE(station::slots_without_part(none, "").empty());
}

TEST(PartCoverage, RunSaysSoBeforeItTouchesADevice) {
  // examples/station.toml's devices are not running here: the run stops at the start check,
  // after the warning.
  const auto db = ts::fresh_db("part-coverage");
  const auto o = ts::station_command(
      "run --config " + example_config(false) + " --db " + db + " --parts " + kParts,
      "part-coverage");
  EXPECT_EQ(o.status, 2) << o.out;
  EXPECT_TRUE(has(o.out, "slot 1 (node 1, serial RLG-0001) names no part")) << o.out;
  EXPECT_TRUE(has(o.out, "slot 2 (node 2, serial RLG-0002) names no part")) << o.out;
  EXPECT_LT(o.out.find("names no part"), o.out.find("unreachable")) << o.out;
  const auto quiet = ts::station_command(
      "run --config " + example_config(false) + " --db " + ts::fresh_db("part-coverage-q"),
      "part-coverage-q");
  EXPECT_FALSE(has(quiet.out, "names no part")) << quiet.out;
}
