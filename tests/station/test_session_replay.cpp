// Issue 8, replay: a recorded session replays through the unchanged daemon to the same samples,
// bins, events and fits; a changed recorded byte that changes a sample makes it differ (bytes
// flipped at many positions, mid-bin included); a changed setpoint is a divergence naming both
// requests; a bad session is one line naming the file.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "station/common/input_error.hpp"
#include "station/session/result_reader.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_replay.hpp"
#include "station/sim/sim_run.hpp"
#include "tests/station/sim_options.hpp"
#include "tests/station/temp_db.hpp"
#include "tests/station/text_file.hpp"

namespace fs = std::filesystem;

namespace {

using station::testing_support::read_lines;
using station::testing_support::write_lines;

// A copy of the recorded session to tamper with.
fs::path copy_of(const fs::path& session, const std::string& name) {
  const fs::path d = session.string() + "." + name;
  fs::remove_all(d);
  fs::copy(session, d, fs::copy_options::recursive);
  return d;
}

int run_station(const std::string& args, std::string& out) {
  const std::string cmd = std::string(STATION_BINARY_DIR) + "/station/station " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int raw = pclose(p);
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

class SessionReplay : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto db = station::testing_support::fresh_db("session_replay");
    dir_ = new fs::path(db + ".session");
    fs::remove_all(*dir_);
    station::SimRunOptions o = station::testing_support::short_cycle_run(db, 2);
    o.record_dir = dir_->string();
    station::run_simulated(o);
  }
  static void TearDownTestSuite() { delete dir_; }
  // A tampered copy is replayed without its digest check (verify false) to see what the daemon
  // makes of it: the digest alone would say "not the recording" (test_session_verify.cpp).
  static station::ReplayReport replay(const fs::path& d, bool verify = false) {
    return station::replay_session({d.string(), "", 0, 0, verify});
  }
  static fs::path* dir_;
};
fs::path* SessionReplay::dir_ = nullptr;

}  // namespace

TEST_F(SessionReplay, AnUntouchedSessionReplaysTheSameEveryTime) {
  for (int i = 0; i < 3; ++i) {
    const auto r = replay(*dir_, true);
    EXPECT_TRUE(r.same) << r.json().dump(1);
    EXPECT_EQ(r.ticks, 8156);  // a step ramps at the station's 3 C/min (issue 20 review fix)
    EXPECT_GT(r.bins, 0);
    EXPECT_EQ(r.fits, 2);
    EXPECT_EQ(r.json()["verdict"], "same");
  }
}

// Every COUNTS frame (ID 0x281/0x282) is a sample's rate: flipping one count byte anywhere —
// mid-bin included, where the cumulative counts cancel in the bin mean — must be seen.
TEST_F(SessionReplay, AFlippedCountByteAnywhereMakesTheReplayDiffer) {
  const auto lines = read_lines(*dir_ / "can.log");
  std::vector<std::size_t> counts;
  for (std::size_t i = 0; i < lines.size(); ++i)
    if (lines[i].find(" can0 281#") != std::string::npos) counts.push_back(i);
  ASSERT_GT(counts.size(), 8000u);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 6; ++trial) {
    const std::size_t at = counts[rng() % counts.size()];
    auto tampered = lines;
    std::string& l = tampered[at];
    const std::size_t data = l.find('#') + 1;
    l[data] = l[data] == '0' ? '1' : '0';  // the low count byte's high nibble
    const auto d = copy_of(*dir_, "flip");
    write_lines(d / "can.log", tampered);
    const auto r = replay(d);
    EXPECT_FALSE(r.same) << "line " << at + 1 << ": " << l;
    EXPECT_TRUE(r.first_difference.dump().find("tick") != std::string::npos)
        << r.first_difference.dump();
    EXPECT_GT(r.max_abs_difference.value("rate_dph", 0.0), 0.0) << r.json().dump(1);
  }
}

// Another setpoint written than the recorded one: the daemon's behaviour changed.
TEST_F(SessionReplay, ADifferentSetpointWrittenIsADivergenceNamingBothRequests) {
  auto lines = read_lines(*dir_ / "modbus.log");
  bool changed = false;
  for (auto& l : lines) {
    // The second setpoint write (40 C = 400 = 0x0190) becomes 41 C (0x019a) in the recording.
    const auto at = l.find(" tx modbus-write 0106012c0190 ");
    if (at == std::string::npos) continue;
    l.replace(at, 30, " tx modbus-write 0106012c019a ");
    changed = true;
    break;
  }
  ASSERT_TRUE(changed);
  const auto d = copy_of(*dir_, "setpoint");
  write_lines(d / "modbus.log", lines);
  const auto r = replay(d);
  ASSERT_FALSE(r.same);
  const auto& f = r.first_difference;
  EXPECT_EQ(f["at"]["device"], "chamber") << f.dump();
  EXPECT_NE(f["recorded"].get<std::string>().find("0106012c019a"), std::string::npos) << f.dump();
  EXPECT_EQ(f["replayed"], "tx modbus-write 0106012c0190") << f.dump();
}

TEST_F(SessionReplay, ABadSessionIsOneLineNamingTheFile) {
  const auto d = copy_of(*dir_, "bad");
  auto header = read_lines(d / "session.toml");
  for (auto& l : header)
    if (l.rfind("format_version", 0) == 0) l = "format_version = 99";
  write_lines(d / "session.toml", header);
  try {
    replay(d);
    FAIL() << "accepted format_version 99";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("session.toml: key 'format_version': 99"),
              std::string::npos)
        << e.what();
  }
  const auto m = copy_of(*dir_, "badlog");
  auto log = read_lines(m / "modbus.log");
  log[2] = "not a line";
  write_lines(m / "modbus.log", log);
  try {
    replay(m);
    FAIL() << "accepted a malformed modbus.log";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("modbus.log:3: bad time 'not'"), std::string::npos)
        << e.what();
  }
  // A result.json cut short (the disk filled while it was written by hand, say): its byte named.
  const auto r = copy_of(*dir_, "badresult");
  auto result = read_lines(r / "result.json");
  result.resize(result.size() - 3);
  write_lines(r / "result.json", result);
  try {
    replay(r);
    FAIL() << "accepted a truncated result.json";
  } catch (const station::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("result.json: byte "), std::string::npos) << what;
    EXPECT_NE(what.find("not JSON"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST_F(SessionReplay, TheCommandExits0Same1Differs2BadSession) {
  std::string out;
  EXPECT_EQ(run_station("replay " + dir_->string() + " --json", out), 0) << out;
  EXPECT_NE(out.find("\"verdict\": \"same\""), std::string::npos) << out;
  const auto d = copy_of(*dir_, "cli");
  auto lines = read_lines(d / "can.log");
  for (std::size_t i = lines.size() / 2; i < lines.size(); ++i) {
    const auto at = lines[i].find(" can0 282#");
    if (at == std::string::npos) continue;
    char& c = lines[i][at + 10];
    c = c == '0' ? '1' : '0';
    break;
  }
  write_lines(d / "can.log", lines);
  out.clear();
  EXPECT_EQ(run_station("replay " + d.string(), out), 1) << out;
  EXPECT_NE(out.find("DIFFERS"), std::string::npos) << out;
  EXPECT_NE(out.find("can.log:"), std::string::npos) << out;  // the digest names the line
  fs::remove(d / "result.json");
  out.clear();
  EXPECT_EQ(run_station("replay " + d.string(), out), 2) << out;
  EXPECT_NE(out.find("result.json: cannot open"), std::string::npos) << out;
}

// The shipped killed_resumed session (tests/sessions/record.sh): SIGKILL before tick 1230, resumed
// after the last committed tick 1199. Each daemon's part of the logs is replayed by its own
// daemon; the killed daemon's ticks 1200..1229 (logged, never committed) are not used.
TEST(SessionReplayResumed, EachDaemonsPartCountsAndTheLostTicksDoNot) {
  const auto d = fs::path(station::testing_support::fresh_db("resumed") + ".session");
  fs::remove_all(d);
  fs::copy(fs::path(STATION_SOURCE_DIR) / "tests/sessions/killed_resumed", d);
  ASSERT_EQ(std::system(("gzip -d " + d.string() + "/*.gz").c_str()), 0);
  const auto resumes = station::read_session_resumes((d / "session.toml").string());
  ASSERT_EQ(resumes.size(), 1u);
  EXPECT_EQ(resumes[0].after_tick_s, 1199.0);
  const auto lines = read_lines(d / "can.log");
  const auto killed_lines = static_cast<std::size_t>(resumes[0].can_lines);
  ASSERT_LT(killed_lines, lines.size());
  std::vector<std::size_t> counts;  // the COUNTS frames of node 1
  for (std::size_t i = 0; i < lines.size(); ++i)
    if (lines[i].find(" can0 281#") != std::string::npos) counts.push_back(i);
  const auto flipped_replay = [&](std::size_t at) {
    auto tampered = lines;
    std::string& l = tampered[at];
    const std::size_t data = l.find('#') + 1;
    l[data] = l[data] == '0' ? '1' : '0';
    const auto t = copy_of(d, "flip");
    write_lines(t / "can.log", tampered);
    return station::replay_session({t.string(), "", 0, 0, false});
  };
  EXPECT_TRUE(station::replay_session({d.string(), "", 0, 0}).same);
  std::size_t first_daemon = 0, lost = 0, second_daemon = 0;
  for (const auto i : counts) {
    if (i < killed_lines / 2 && first_daemon == 0) first_daemon = i;
    if (i < killed_lines) lost = i;  // the last one the killed daemon logged: tick 1229
    if (i > killed_lines + 100 && second_daemon == 0) second_daemon = i;
  }
  EXPECT_FALSE(flipped_replay(first_daemon).same) << lines[first_daemon];
  EXPECT_FALSE(flipped_replay(second_daemon).same) << lines[second_daemon];
  const auto r = flipped_replay(lost);
  EXPECT_TRUE(r.same) << lines[lost] << "\n" << r.json().dump(1);
  // A rig's restart tick came from the wall clock: a resume that does not say it is refused.
  const auto rig = copy_of(d, "rig");
  auto header = read_lines(rig / "session.toml");
  std::erase_if(header, [](const std::string& l) {
    return l.rfind("sim_seed", 0) == 0 || l.rfind("next_tick_s", 0) == 0;
  });
  write_lines(rig / "session.toml", header);
  try {
    station::replay_session({rig.string(), "", 0, 0, false});
    FAIL() << "replayed a rig resume without its next tick";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("session.toml: resume 1: key 'next_tick_s' missing"),
              std::string::npos)
        << e.what();
  }
}

// Fuzz finding (fuzz_result_json): a "ticks" that is not an array stayed in the head, where the
// comparison would have seen no ticks at all. Now one line naming the key.
TEST(ResultReader, TicksThatAreNotAnArrayAreABadFile) {
  const auto path = station::testing_support::fresh_db("ticks_object") + ".json";
  std::ofstream(path) << "{\"ticks\": {\"ticks\": [3]}}\n";
  int handed = 0;
  try {
    station::read_result_file(path, [&handed](nlohmann::json&&) { ++handed; });
    FAIL() << "accepted a ticks object";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(".json: key 'ticks': not an array"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(handed, 0);
  std::ofstream(path) << "{\"ticks\": [[1.0], [2.0]], \"state\": \"completed\"}\n";
  const auto head = station::read_result_file(path, [&handed](nlohmann::json&&) { ++handed; });
  EXPECT_EQ(handed, 2);
  EXPECT_EQ(head["state"], "completed");
}
