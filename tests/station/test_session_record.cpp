// Issue 8, recording: `run --sim --record DIR` writes a session directory as schemas/session.md
// says, every log on the run's (simulated) clock, and result.json equal to what was stored.
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/can/candump_log.hpp"
#include "sim_devices/sim_world.hpp"
#include "station/session/session_files.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/store.hpp"
#include "tests/station/sim_options.hpp"
#include "tests/station/temp_db.hpp"
#include "tests/station/text_file.hpp"

namespace fs = std::filesystem;

namespace {

using station::testing_support::read_lines;

std::vector<std::string> fields(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string f; in >> f;) out.push_back(f);
  return out;
}

// One simulated session, recorded once for every test of this file.
class SessionRecord : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    db_ = new std::string(station::testing_support::fresh_db("session_record"));
    dir_ = new fs::path(*db_ + ".session");
    fs::remove_all(*dir_);
    station::SimRunOptions o = station::testing_support::short_cycle_run(*db_, 2);
    o.record_dir = dir_->string();
    report_ = new nlohmann::json(station::run_simulated(o));
  }
  static void TearDownTestSuite() {
    delete report_;
    delete dir_;
    delete db_;
  }
  static std::string* db_;
  static fs::path* dir_;
  static nlohmann::json* report_;
};
std::string* SessionRecord::db_ = nullptr;
fs::path* SessionRecord::dir_ = nullptr;
nlohmann::json* SessionRecord::report_ = nullptr;

}  // namespace

TEST_F(SessionRecord, TheHeaderSaysWhatTheRunWas) {
  const auto t = toml::parse_file((*dir_ / "session.toml").string());
  EXPECT_EQ(t["format_version"].value<int>(), station::kSessionFormatVersion);
  EXPECT_EQ(t["simulated"].value<bool>(), true);
  EXPECT_EQ(t["protocol_name"].value<std::string>(), "short_cycle");
  const auto* slots = t["slot"].as_array();
  ASSERT_NE(slots, nullptr);
  ASSERT_EQ(slots->size(), 2u);
  EXPECT_EQ((*slots)[1].as_table()->get("serial")->value<std::string>(), "SIM-0002");
  // The protocol and configuration are there verbatim.
  EXPECT_NE(t["protocol"].value<std::string>()->find("record 0 -> 40 C"), std::string::npos);
  EXPECT_NE(t["config"].value<std::string>()->find("[[slot]]"), std::string::npos);
}

// 8 h of simulated traffic must span 8 h of stamps, not the seconds the simulation took.
TEST_F(SessionRecord, TheCanLogIsOnTheSimulatedClock) {
  const auto records = station::drivers::can::read_candump_log((*dir_ / "can.log").string());
  ASSERT_GT(records.size(), 100u);
  const auto t = [](const station::drivers::can::CandumpRecord& r) {
    return static_cast<double>(r.time_sec) + 1e-6 * r.time_usec;
  };
  const double span_s = t(records.back()) - t(records.front());
  const double sim_s = (*report_)["sim_s"].get<double>();
  EXPECT_NEAR(span_s, sim_s, 1.0) << "simulated " << sim_s << " s";
  for (std::size_t i = 1; i < records.size(); ++i)
    ASSERT_GE(t(records[i]), t(records[i - 1])) << "line " << i + 1;
}

TEST_F(SessionRecord, ModbusAndGpioLogsHoldEveryExchangeOneLineEach) {
  int reads = 0, writes = 0, setpoint_writes = 0;
  for (const auto& line : read_lines(*dir_ / "modbus.log")) {
    const auto f = fields(line);
    ASSERT_GE(f.size(), 5u) << line;
    EXPECT_TRUE(f[1] == "chamber" || f[1] == "turntable") << line;
    EXPECT_TRUE(f[2] == "tx" || f[2] == "rx" || f[2] == "event") << line;
    EXPECT_TRUE(f[4] == "-" || f[4].size() % 2 == 0) << line;
    reads += f[3] == "modbus-read" && f[2] == "rx" ? 1 : 0;
    if (f[3] == "modbus-write" && f[2] == "tx") {
      ++writes;
      // unit 1, fc 6, address 300 (0x012c, the F4 setpoint): the value written is in the line.
      setpoint_writes += f[4].rfind("0106012c", 0) == 0 && f[4].size() == 12 ? 1 : 0;
    }
  }
  const double sim_s = (*report_)["sim_s"].get<double>();
  EXPECT_GE(reads, static_cast<int>(sim_s)) << "a chamber read every tick at least";
  EXPECT_GT(writes, 0);
  EXPECT_GE(setpoint_writes, 2) << "0 C, then 40 C";
  int gpio_reads = 0, gpio_writes = 0;
  for (const auto& line : read_lines(*dir_ / "gpio.log")) {
    const auto f = fields(line);
    ASSERT_GE(f.size(), 6u) << line;
    gpio_reads += f[3] == "gpio-read" ? 1 : 0;
    gpio_writes += f[3] == "gpio-write" ? 1 : 0;
  }
  EXPECT_GE(gpio_reads, 2 * static_cast<int>(sim_s)) << "interlock and e-stop every tick";
  EXPECT_GE(gpio_writes, 2) << "the green lamp and the power relays at least";
}

TEST_F(SessionRecord, TheResultIsWhatTheStoreHolds) {
  std::ifstream in(*dir_ / "result.json");
  const auto r = nlohmann::json::parse(in);
  EXPECT_EQ(r["format_version"], station::kSessionFormatVersion);
  EXPECT_EQ(r["state"], "completed");
  // Recomputed from the database after the run: the same JSON, value for value.
  station::Store store(*db_, station::OpenMode::read_only);
  EXPECT_EQ(r, station::session_result_json(store, r["run_id"].get<std::int64_t>()));
  const double sim_s = (*report_)["sim_s"].get<double>();
  EXPECT_EQ(r["ticks"].size(), static_cast<std::size_t>(sim_s) + 1);
  EXPECT_EQ(r["ticks"][10].size(), 3u);  // [t_s, row, row]
  EXPECT_FALSE(r["bins"].empty());
  ASSERT_EQ(r["fits"].size(), 2u);
  EXPECT_TRUE(r["fits"][0]["coefficients"].contains("k1"));
  bool started = false;
  for (const auto& e : r["events"]) started = started || e["kind"] == "run_start";
  EXPECT_TRUE(started);
}

// A simulation stopped and resumed with --record goes on in the same directory: the resumed
// process replays its stored ticks silently, so every SYNC is in can.log exactly once, in time
// order, and result.json holds every tick once.
TEST(SessionRecordResume, AResumedSimulationAppendsEachExchangeOnce) {
  const auto db = station::testing_support::fresh_db("session_resume");
  const fs::path dir = db + ".session";
  fs::remove_all(dir);
  std::atomic<bool> stop{false};
  station::SimRunOptions o = station::testing_support::short_cycle_run(db, 1);
  o.record_dir = dir.string();
  o.stop = &stop;
  o.on_world_tick = [&stop](double t_s, station::sim::SimWorld&) {
    if (t_s >= 3000) stop = true;
  };
  ASSERT_EQ(station::run_simulated(o)["state"], "stopped");
  // The stopped run is finished as 'stopped'; resuming needs an unfinished one, as a kill
  // leaves it.
  {
    station::Store s(db, station::OpenMode::existing);
    s.db().exec("UPDATE runs SET state = 'running' WHERE id = 1");
  }
  stop = false;
  o.fresh = false;
  o.on_world_tick = nullptr;
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed");
  const auto records = station::drivers::can::read_candump_log((dir / "can.log").string());
  std::vector<double> syncs;
  for (const auto& c : records)
    if (c.frame.can_id == 0x080) syncs.push_back(c.time_sec + 1e-6 * c.time_usec);
  EXPECT_EQ(syncs.size(), static_cast<std::size_t>(r["sim_s"].get<double>()) + 1);
  for (std::size_t i = 1; i < syncs.size(); ++i) ASSERT_GT(syncs[i], syncs[i - 1]) << i;
  std::ifstream in(dir / "result.json");
  const auto result = nlohmann::json::parse(in);
  EXPECT_EQ(result["ticks"].size(), syncs.size());
}
