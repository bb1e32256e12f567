// Issue 31: one host, four ways in. One scripted sequence of rig faults (door, e-stop, a chamber
// disconnect, a CAN drop, a kill and a resume) is run by `run --sim` (the simulated rig on the
// simulated clock), by `run --config` against simrig (real loopback stacks on the wall clock) and
// by a run started through `serve`'s API against simrig (the two wall-clock legs side by side,
// each on its own simrig); the sim's and the rig's sessions are recorded and replayed.
// All four go through daemon/host and daemon/run_start, so they must agree:
//  * the same run state at the end and one resume;
//  * the same fault events (kind and source), in the same order;
//  * the same committed samples: on the simulated clock exactly (replay says "same"); between the
//    simulated and the wall-clock runs the same share of each flag over the ticks both kept (a
//    fault injected between two wall-clock ticks may land one tick early or late: one tick per
//    fault edge is the tolerance), and a wall-clock rig misses only the ticks of its down time.
// Where they are meant to differ, by the one start rule: a simulation resumes by replaying from
// t = 0 (its first daemon's batch of ticks is recomputed), a rig at the elapsed time (a gap).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "sim_devices/control_socket.hpp"
#include "station/store/run_state.hpp"
#include "station/store/store.hpp"
#include "tests/station/rig_process.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace ts = station::testing_support;
using namespace std::chrono_literals;

struct Fault {
  double t_s;
  std::string command;  // simrig's control language (docs/SIMRIG.md)
};
const std::vector<Fault> kScript{{6, "door open"},
                                 {9, "door close"},
                                 {13, "estop press"},
                                 {16, "estop release"},
                                 {20, "chamber disconnect 2"},
                                 {25, "can drop 3"}};
constexpr double kKillBeforeS = 29;  // the daemon is SIGKILLed before this tick, then restarted
constexpr int kHoldS = 36;

std::string write_protocol(const std::string& dir) {
  const std::string path = dir + "/one_host.toml";
  std::ofstream(path) << "name = \"one_host\"\n\n[[step]]\ntype = \"record_start\"\n\n[[step]]\n"
                         "type = \"hold\"\nduration_s = "
                      << kHoldS << "\n";
  return path;
}

/// A rig loses the ticks of its down time (a simulation replays them): the kill's few seconds of
/// a short run must not make it 'incomplete' (the configured share, [station] max_lost_share).
void allow_down_time(const std::string& config_path) {
  std::string text = ts::slurp(config_path);
  const auto at = text.find("ref_temp_c = ");
  ASSERT_NE(at, std::string::npos) << text;
  text.insert(text.find('\n', at) + 1, "max_lost_share = 0.5\n");
  std::ofstream(config_path) << text;
}

/// The daemon's store read-only; empty while the daemon has not created it.
std::optional<station::Store> open_store(const std::string& db) {
  try {
    return std::optional<station::Store>(std::in_place, db, station::OpenMode::read_only);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// The first gyro's samples of run 1 (empty before there are any).
std::vector<station::SampleRow> first_gyro_samples(station::Store& s) {
  const auto slots = s.run_slots(1);
  return slots.empty() ? std::vector<station::SampleRow>{} : s.samples(1, slots[0].serial, false);
}

double last_tick(const std::string& db) {
  auto s = open_store(db);
  const auto rows = s ? first_gyro_samples(*s) : std::vector<station::SampleRow>{};
  return rows.empty() ? -1.0 : rows.back().t_s;
}

/// What a run left: its state, its fault events in order, its samples' flags by tick.
struct Outcome {
  std::vector<std::string> states;
  std::vector<std::string> fault_events;  // "kind source"
  int resumes = 0;
  std::map<int, int> flags;  // tick -> flags of the first gyro
};

Outcome outcome_of(const std::string& db) {
  Outcome o;
  auto s = open_store(db);
  if (!s) return o;
  for (std::int64_t id = 1; const auto run = s->find_run(id); ++id)
    o.states.emplace_back(station::to_string(run->state));
  static const std::set<std::string> kFaultKinds{"safe_hold", "safe_hold_cleared", "outage_start",
                                                 "outage"};
  for (const auto& e : s->event_rows(1)) {
    if (e.kind == "resume") ++o.resumes;
    // A CAN outage is one per board: the first board's stands for the bus.
    const bool other_board = e.source.rfind("can node", 0) == 0 && e.source != "can node 1";
    if (kFaultKinds.count(e.kind) && !other_board)
      o.fault_events.push_back(e.kind + " " + e.source);
  }
  for (const auto& r : first_gyro_samples(*s)) o.flags[static_cast<int>(r.t_s)] = r.flags;
  return o;
}

/// Plays the script against a daemon on `rig`: each fault once the daemon committed the tick
/// before it, the kill before kKillBeforeS; `restart` starts the daemon again. The daemon's pid.
pid_t play_script(const std::string& control_path, const std::string& db, pid_t daemon,
                  const std::function<pid_t()>& restart) {
  auto reached = [&](double t_s) {
    return ts::wait_until([&] { return last_tick(db) >= t_s - 1; }, 60s);
  };
  for (const auto& f : kScript) {
    EXPECT_TRUE(reached(f.t_s)) << "the daemon never reached t = " << f.t_s << " s";
    EXPECT_EQ(station::sim::send_control_commands(control_path, {f.command}).at(0).rfind("ok", 0),
              0u)
        << f.command;
  }
  EXPECT_TRUE(reached(kKillBeforeS));
  kill(daemon, SIGKILL);
  waitpid(daemon, nullptr, 0);
  std::this_thread::sleep_for(3s);  // a rig resumes at the elapsed time: a gap
  return restart();
}

std::string replay(const std::string& session, const std::string& tag) {
  const pid_t p = ts::spawn_process({ts::kStationBin, "replay", session}, tag + ".replay.out",
                                    tag + ".replay.err");
  const int st = ts::wait_bounded(p, 120s);
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0)
      << ts::slurp(tag + ".replay.out") << ts::slurp(tag + ".replay.err");
  return ts::slurp(tag + ".replay.out");
}

/// Ticks of `o` with flag bit `bit`, over the ticks `other` kept too.
int ticks_with(const Outcome& o, const Outcome& other, int bit) {
  int n = 0;
  for (const auto& [t, f] : o.flags)
    if (other.flags.count(t) && (f & bit) != 0) ++n;
  return n;
}

class OneHost : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "one-host-" + std::to_string(getpid());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    protocol_ = write_protocol(dir_);
  }
  /// run --config against simrig, the script through simrig's control socket.
  void run_on_simrig(Outcome& out) {
    const std::string ctl = dir_ + "/rig.ctl";
    ts::SimrigProcess rig;
    rig.extra_args = {"--control", ctl};
    ASSERT_TRUE(rig.start("one-host-rig")) << ts::slurp(rig.err);
    allow_down_time(rig.config_path);
    const std::string db = dir_ + "/rig.db";
    int lives = 0;
    const std::function<pid_t()> start = [&] {
      ++lives;
      return ts::spawn_process({ts::kStationBin, "run", "--config", rig.config_path, "--protocol",
                                protocol_, "--db", db, "--record", dir_ + "/rig.session"},
                               fmt::format("{}.{}.out", db, lives),
                               fmt::format("{}.{}.err", db, lives));
    };
    const int st = ts::wait_bounded(play_script(ctl, db, start(), start), 120s);
    ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << ts::slurp(db + ".2.err");
    out = outcome_of(db);
  }

  /// serve, the run started by the API; the killed service resumes it at its next start.
  void serve_through_api(Outcome& out) {
    ts::SimrigProcess rig;
    const std::string ctl = dir_ + "/rig2.ctl";
    rig.extra_args = {"--control", ctl};
    ASSERT_TRUE(rig.start("one-host-api")) << ts::slurp(rig.err);
    allow_down_time(rig.config_path);
    std::ofstream(rig.config_path, std::ios::app)
        << "\n[http]\nprotocol_dir = \"" << dir_ << "\"\n";
    const std::string db = dir_ + "/api.db";
    int lives = 0;
    const std::function<pid_t()> start = [&] {
      ++lives;
      return ts::spawn_process({ts::kStationBin, "serve", "--config", rig.config_path, "--db", db,
                                "--http", "127.0.0.1:0"},
                               fmt::format("{}.{}.out", db, lives),
                               fmt::format("{}.{}.err", db, lives));
    };
    pid_t service = start();
    std::string port;
    ASSERT_TRUE(ts::wait_until(
        [&] {
          const std::string text = ts::slurp(db + ".1.out");
          const auto at = text.find("127.0.0.1:");
          if (at == std::string::npos) return false;
          port = text.substr(at + 10, text.find_first_not_of("0123456789", at + 10) - at - 10);
          return !port.empty();
        },
        20s))
        << ts::slurp(db + ".1.err");
    const std::string token = ts::slurp(db + ".token");
    const pid_t curl = ts::spawn_process(
        {"/usr/bin/curl", "-s", "-o", db + ".post", "-w", "%{http_code}", "-X", "POST", "-H",
         "Authorization: Bearer " + token.substr(0, token.find_first_of("\r\n")), "-H",
         "Content-Type: application/json", "-d", R"({"protocol":"one_host","operator":"t"})",
         "http://127.0.0.1:" + port + "/api/runs"},
        db + ".curl.out", db + ".curl.err");
    ts::wait_bounded(curl, 20s);
    ASSERT_EQ(ts::slurp(db + ".curl.out"), "202") << ts::slurp(db + ".post");
    service = play_script(ctl, db, service, start);
    EXPECT_TRUE(ts::wait_until(
        [&] {
          const auto states = outcome_of(db).states;
          return !states.empty() && states[0] != "running";
        },
        120s));
    kill(service, SIGTERM);
    ts::wait_bounded(service, 20s);
    out = outcome_of(db);
  }

  std::string dir_, protocol_;
};

TEST_F(OneHost, OneFaultScriptGivesTheSameRunUnderSimRigApiAndReplay) {
  // 1. run --sim: the script as --fault options, the kill too; run again to resume.
  const std::string sim_db = dir_ + "/sim.db", sim_session = dir_ + "/sim.session";
  std::vector<std::string> sim{ts::kStationBin, "run",     "--sim", "--gyros", "2",
                               "--protocol",    protocol_, "--db",  sim_db,    "--record",
                               sim_session};
  for (const auto& f : kScript)
    sim.insert(sim.end(), {"--fault", fmt::format("{}:{}", f.t_s, f.command)});
  auto killed = sim;
  killed.insert(killed.end(), {"--fault", fmt::format("{}:kill", kKillBeforeS)});
  int st = ts::wait_bounded(ts::spawn_process(killed, sim_db + ".a.out", sim_db + ".a.err"), 120s);
  ASSERT_TRUE(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL) << ts::slurp(sim_db + ".a.err");
  st = ts::wait_bounded(ts::spawn_process(sim, sim_db + ".b.out", sim_db + ".b.err"), 120s);
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << ts::slurp(sim_db + ".b.err");
  const Outcome want = outcome_of(sim_db);

  // 2. and 3., side by side: each its own simrig on the wall clock.
  Outcome rig_run, api_run;
  std::thread rig_leg([&] { run_on_simrig(rig_run); });
  serve_through_api(api_run);
  rig_leg.join();

  // The same run, four ways.
  EXPECT_EQ(want.states, (std::vector<std::string>{"completed"}));
  EXPECT_EQ(want.resumes, 1);
  EXPECT_EQ(want.flags.size(), static_cast<std::size_t>(kHoldS + 1)) << "sim replays from 0";
  for (const auto* got : {&rig_run, &api_run}) {
    SCOPED_TRACE(got == &rig_run ? "run --config on simrig" : "serve's API on simrig");
    EXPECT_EQ(got->states, want.states);
    EXPECT_EQ(got->resumes, 1);
    EXPECT_EQ(got->fault_events, want.fault_events);
    // A rig resumes at the elapsed time: the down time is missing, nothing else.
    EXPECT_LT(got->flags.size(), want.flags.size());
    EXPECT_GE(got->flags.size(), want.flags.size() - 6);
    for (const int bit : {1, 2, 4, 8, 16, 32, 64, 128}) {
      const int a = ticks_with(want, *got, bit), b = ticks_with(*got, want, bit);
      EXPECT_LE(std::abs(a - b), 2) << "flag bit " << bit << ": sim " << a << ", rig " << b;
    }
  }
  EXPECT_NE(replay(sim_session, sim_db).find(": same"), std::string::npos);
  EXPECT_NE(replay(dir_ + "/rig.session", dir_ + "/rig.db").find(": same"), std::string::npos);
}

}  // namespace

namespace {

// A simulation commits its ticks in batches: killed before the first commit (before its first
// tick, or a few ticks in), it leaves a run with no tick (after_tick_s = -1 in the session). The
// resumed run and the recording of both daemons must still replay "same".
TEST_F(OneHost, ASimulationKilledBeforeItsFirstCommitResumesAndReplays) {
  for (const int kill_at : {0, 5}) {
    SCOPED_TRACE("killed before tick " + std::to_string(kill_at));
    const std::string db = fmt::format("{}/early{}.db", dir_, kill_at);
    const std::string session = db + ".session";
    const std::vector<std::string> run{ts::kStationBin, "run",     "--sim", "--gyros", "1",
                                       "--protocol",    protocol_, "--db",  db,        "--record",
                                       session};
    auto killed = run;
    killed.insert(killed.end(), {"--fault", fmt::format("{}:kill", kill_at)});
    int st = ts::wait_bounded(ts::spawn_process(killed, db + ".a.out", db + ".a.err"), 60s);
    ASSERT_TRUE(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL) << ts::slurp(db + ".a.err");
    EXPECT_EQ(open_store(db)->sample_count(1), 0);
    st = ts::wait_bounded(ts::spawn_process(run, db + ".b.out", db + ".b.err"), 60s);
    ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << ts::slurp(db + ".b.err");
    EXPECT_EQ(outcome_of(db).states, (std::vector<std::string>{"completed"}));
    EXPECT_NE(replay(session, db).find(": same"), std::string::npos);
  }
}

}  // namespace
