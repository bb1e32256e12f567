// Issue 19, items 11-12: a stopped or aborted run's recording replays to its end with the same
// state; a recording that is not the one the run made never replays "same": events compared as
// an ordered list with their data, every field of every fit, the session's own metadata, and
// every file against the digest written when the run ended (a changed byte named by file and
// line). Tamperings of the shipped sessions through the command: tests/sessions/tamper.py.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "station/common/input_error.hpp"
#include "station/daemon/sequencer.hpp"
#include "station/session/session_digest.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_replay.hpp"
#include "station/sim/sim_run.hpp"
#include "tests/station/sim_options.hpp"
#include "tests/station/temp_db.hpp"
#include "tests/station/text_file.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using station::testing_support::read_lines;
using station::testing_support::write_lines;

namespace {

// A simulated short_cycle run on one gyro recorded in a fresh directory; `end_at` (when set)
// stops or aborts it after that tick, as SIGINT or POST .../abort would.
fs::path record(const std::string& name, const std::string& how = "", double end_at = 0) {
  const auto db = station::testing_support::fresh_db(name);
  const fs::path dir = db + ".session";
  fs::remove_all(dir);
  std::atomic<bool> stop{false}, abort{false};
  station::SimRunOptions o = station::testing_support::short_cycle_run(db, 1);
  o.record_dir = dir.string();
  o.stop = &stop;
  o.extend = [&abort](station::SequencerOptions& s) { s.abort = &abort; };
  o.faults = {{1500, "can drop 3"}};  // an outage: an event with data (ticks_lost)
  o.on_world_tick = [&](double t_s, station::sim::SimWorld&) {
    if (how.empty() || t_s != end_at) return;
    (how == "stop" ? stop : abort) = true;
  };
  const auto report = station::run_simulated(o);
  EXPECT_EQ(report["state"], how == "stop" ? "stopped" : how == "abort" ? "aborted" : "completed");
  return dir;
}

station::ReplayReport replay(const fs::path& d, bool verify = true) {
  return station::replay_session({d.string(), "", 0, 0, verify});
}

fs::path copy_of(const fs::path& d, const std::string& name) {
  const fs::path c = d.string() + "." + name;
  fs::remove_all(c);
  fs::copy(d, c, fs::copy_options::recursive);
  return c;
}

json read_json(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

class SessionVerify : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { dir_ = new fs::path(record("session_verify")); }
  static void TearDownTestSuite() { delete dir_; }
  // A copy whose result.json is `edit`ed (the digest not checked: what the daemon makes of it).
  static station::ReplayReport with_result(const std::string& name,
                                           const std::function<void(json&)>& edit) {
    const auto c = copy_of(*dir_, name);
    json r = read_json(c / "result.json");
    edit(r);
    std::ofstream(c / "result.json") << r.dump();
    return replay(c, false);
  }
  static fs::path* dir_;
};
fs::path* SessionVerify::dir_ = nullptr;

}  // namespace

// Item 11: before, the replayed run went on past the stop and found no more exchanges.
TEST(SessionEnd, AStoppedRunReplaysToItsStopWithTheSameState) {
  const auto d = record("session_stopped", "stop", 2000);
  const auto end = station::read_session_end((d / "session.toml").string());
  EXPECT_EQ(end.state, "stopped");
  EXPECT_EQ(end.last_tick_s, 2000.0);
  const auto r = replay(d);
  EXPECT_TRUE(r.same) << r.json().dump(1);
  EXPECT_EQ(r.ticks, 2001);
  EXPECT_EQ(read_json(d / "result.json")["state"], "stopped");
}

TEST(SessionEnd, AnAbortedRunReplaysToItsAbortWithTheSameState) {
  const auto d = record("session_aborted", "abort", 2500);
  EXPECT_EQ(station::read_session_end((d / "session.toml").string()).state, "aborted");
  const auto r = replay(d);
  EXPECT_TRUE(r.same) << r.json().dump(1);
  EXPECT_EQ(r.ticks, 2501);
  EXPECT_EQ(r.fits, 0);
  // The end moved one tick later: the replayed run is not the recorded one.
  const auto c = copy_of(d, "later");
  auto header = read_lines(c / "session.toml");
  for (auto& l : header)
    if (l.rfind("last_tick_s", 0) == 0) l = "last_tick_s = 2501.0";
  write_lines(c / "session.toml", header);
  EXPECT_FALSE(replay(c, false).same);
}

TEST_F(SessionVerify, TheUntouchedSessionIsTheSame) {
  const auto r = replay(*dir_);
  EXPECT_TRUE(r.same) << r.json().dump(1);
  EXPECT_FALSE(station::verify_session_digest(dir_->string()));
}

// Item 12: each of these replayed "same" before.
TEST_F(SessionVerify, AnEventsDataChangedDiffers) {
  int outages = 0;
  const auto r = with_result("data", [&outages](json& res) {
    for (auto& e : res["events"])
      if (e["data"].is_object() && e["data"].contains("ticks_lost")) {
        e["data"]["ticks_lost"] = e["data"]["ticks_lost"].get<int>() + 100;
        ++outages;
        break;
      }
  });
  ASSERT_EQ(outages, 1);
  EXPECT_FALSE(r.same);
  EXPECT_EQ(r.first_difference["quantity"], "event") << r.first_difference.dump();
}

TEST_F(SessionVerify, AnEventDuplicatedOrReorderedDiffers) {
  auto r = with_result("dup", [](json& res) {
    auto& ev = res["events"];
    ev.insert(ev.begin() + 2, ev[2]);
  });
  EXPECT_FALSE(r.same);
  EXPECT_EQ(r.first_difference["at"]["event"], 3) << r.first_difference.dump();
  r = with_result("swap", [](json& res) { std::swap(res["events"][1], res["events"][2]); });
  EXPECT_FALSE(r.same);
  EXPECT_EQ(r.first_difference["at"]["event"], 1) << r.first_difference.dump();
}

TEST_F(SessionVerify, AFitsWarningTextChangedDiffers) {
  const auto r = with_result("warn", [](json& res) {
    ASSERT_FALSE(res["fits"].empty());
    res["fits"][0]["warnings"].push_back("condition number 1.0e+09");
  });
  EXPECT_FALSE(r.same);
  const auto r2 = with_result("field", [](json& res) { res["fits"][0]["dof_extra"] = 1; });
  EXPECT_FALSE(r2.same);
}

TEST_F(SessionVerify, TheSampleColumnsHeaderPermutedDiffers) {
  const auto r = with_result("columns", [](json& res) {
    std::swap(res["sample_columns"][4], res["sample_columns"][5]);  // temp_c <-> temp2_c
  });
  EXPECT_FALSE(r.same);
  EXPECT_EQ(r.first_difference["quantity"], "sample_columns") << r.first_difference.dump();
}

TEST_F(SessionVerify, TheHeadersResolvedJsonOrSlotsChangedDiffer) {
  for (const std::string key : {"resolved_json", "pulse_weight_arcsec", "latitude_deg"}) {
    const auto c = copy_of(*dir_, "header");
    auto header = read_lines(c / "session.toml");
    bool changed = false;
    for (auto& l : header) {
      if (l.rfind(key + " = ", 0) != 0 || changed) continue;
      const auto at = l.find_first_of("0123456789", key.size());
      l[at] = l[at] == '1' ? '2' : '1';
      changed = true;
    }
    ASSERT_TRUE(changed) << key;
    write_lines(c / "session.toml", header);
    const auto r = replay(c, false);
    EXPECT_FALSE(r.same) << key;
    EXPECT_NE(r.first_difference.dump().find("session.toml"), std::string::npos)
        << r.first_difference.dump();
  }
}

// Any changed byte of any digested file is named by file and line; gzip'd files verify as the
// plain ones.
TEST_F(SessionVerify, AChangedByteAnywhereIsNamedByFileAndLine) {
  std::mt19937 rng(19);
  for (const auto& name : station::digested_files()) {
    const auto lines = read_lines(*dir_ / name);
    if (name == "ascii.log" && lines.empty()) continue;  // no ASCII device on this rig
    ASSERT_GT(lines.size(), 10u) << name;
    for (int trial = 0; trial < 8; ++trial) {
      const std::size_t at = rng() % lines.size();
      auto tampered = lines;
      std::string& l = tampered[at];
      if (l.empty()) continue;
      char& c = l[rng() % l.size()];
      c = static_cast<char>(c ^ (1 << (rng() % 7)));
      const auto t = copy_of(*dir_, "byte");
      write_lines(t / name, tampered);
      const auto m = station::verify_session_digest(t.string());
      ASSERT_TRUE(m) << name << ":" << at + 1;
      EXPECT_EQ(fs::path(m->file).filename(), name);
      EXPECT_EQ(m->line, static_cast<std::int64_t>(at + 1)) << m->message();
      const auto r = replay(t);
      EXPECT_FALSE(r.same);
      EXPECT_EQ(r.first_difference["quantity"], "digest");
    }
  }
  const auto g = copy_of(*dir_, "gz");
  // Compressed as tests/sessions/record.sh ships them (session.toml stays plain): the same bytes.
  ASSERT_EQ(std::system(("cd " + g.string() + " && gzip -n *.log result.json digest.txt").c_str()),
            0);
  EXPECT_FALSE(station::verify_session_digest(g.string()));
  EXPECT_TRUE(replay(g).same);
}

TEST_F(SessionVerify, ANonFiniteOrNegativeToleranceIsABadRequest) {
  for (const auto& [rtol, atol] : std::vector<std::pair<double, double>>{
           {NAN, 0}, {-1, 0}, {0, -1}, {0, INFINITY}, {INFINITY, 0}, {0, NAN}}) {
    EXPECT_THROW(station::replay_session({dir_->string(), "", rtol, atol}), station::InputError)
        << rtol << " " << atol;
  }
}

// A session of format 2 (no digest, no [[end]]) is refused with one line saying why.
TEST_F(SessionVerify, AnOlderFormatIsRefusedWithItsReason) {
  const auto c = copy_of(*dir_, "v2");
  fs::remove(c / "digest.txt");  // version 2 wrote none
  auto header = read_lines(c / "session.toml");
  for (auto& l : header)
    if (l.rfind("format_version", 0) == 0) l = "format_version = 2";
  write_lines(c / "session.toml", header);
  try {
    replay(c);
    FAIL() << "replayed a format-2 session";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("format_version': 2 has no digest"), std::string::npos)
        << e.what();
  }
}
