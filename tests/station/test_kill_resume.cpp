// kill -9 at random instants, restart: no committed sample is lost and the run ends with the
// same fit as an uninterrupted one (the simulation is deterministic from its seed).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <tuple>

#include "station/store/store.hpp"
#include "tests/station/temp_db.hpp"

extern char** environ;

namespace {

const std::string kStation = std::string(STATION_BINARY_DIR) + "/station/station";
const std::string kProtocol = std::string(STATION_TEST_DATA_DIR) + "/short_cycle.toml";

using station::testing_support::fresh_db;

// Starts `station run --sim` on `db`; output discarded.
pid_t spawn_run(const std::string& db) {
  std::vector<std::string> args{kStation, "run",  "--sim", "--gyros",    "2",      "--seed",
                                "5",      "--db", db,      "--protocol", kProtocol};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  posix_spawn(&pid, kStation.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

using Key = std::tuple<std::string, double>;
using Snapshot =
    std::map<Key,
             std::tuple<std::optional<std::int64_t>, std::optional<double>, std::optional<double>>>;

Snapshot snapshot_of_run(station::Store& s, std::int64_t run_id) {
  Snapshot out;
  for (const auto& slot : s.run_slots(run_id)) {
    for (const auto& r : s.samples(run_id, slot.serial, false)) {
      out[{r.serial, r.t_s}] = {r.net_pulses, r.rate_dph, r.temp_c};
    }
  }
  return out;
}

// Samples committed so far (0 while the database does not exist yet).
std::int64_t committed_samples(const std::string& db) {
  try {
    station::Store s(db, station::OpenMode::read_only);
    auto st = s.db().prepare("SELECT count(*) FROM samples");
    return st.step() ? st.column_int(0) : 0;
  } catch (const std::exception&) {
    return 0;
  }
}

// Every sample of the run a killed daemon left unfinished.
Snapshot snapshot(const std::string& db) {
  station::Store s(db);
  auto run = s.find_unfinished_run();
  return run ? snapshot_of_run(s, run->id) : Snapshot{};
}

}  // namespace

TEST(KillResume, KillNineTwiceLosesNothingAndEndsWithTheSameFit) {
  const auto clean_db = fresh_db("clean");
  ASSERT_EQ(wait_exit(spawn_run(clean_db)), 0);

  const auto db = fresh_db("killed");
  // Seeded: each kill comes after a drawn number of further samples is committed (of 16,202 in
  // the run) and a drawn delay of up to 10 ms, so it lands mid-run whatever the machine's
  // speed (a kill on the wall clock alone found a fast run already finished), and anywhere
  // between two commits.
  std::mt19937 rng(20260);
  std::uniform_int_distribution<std::int64_t> more_samples(1000, 5000);
  std::uniform_int_distribution<int> delay_us(0, 10'000);
  Snapshot committed;  // every sample seen committed after any of the kills
  for (int k = 0; k < 2; ++k) {
    const std::int64_t target = committed_samples(db) + more_samples(rng);
    const pid_t pid = spawn_run(db);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (committed_samples(db) < target && std::chrono::steady_clock::now() < give_up)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    kill(pid, SIGKILL);
    ASSERT_EQ(wait_exit(pid), -SIGKILL);
    const Snapshot before = snapshot(db);
    committed.insert(before.begin(), before.end());
  }
  // Restart and let it finish: every sample committed before either kill is still there,
  // unchanged, in the one run that was resumed.
  ASSERT_EQ(wait_exit(spawn_run(db)), 0);
  {
    station::Store s(db);
    const auto runs = s.runs_of_serial("SIM-0001");
    ASSERT_EQ(runs.size(), 1u) << "the restarts resumed the same run";
    const Snapshot after = snapshot_of_run(s, runs[0]);
    for (const auto& [key, v] : committed) {
      const auto it = after.find(key);
      ASSERT_NE(it, after.end()) << std::get<0>(key) << " t=" << std::get<1>(key);
      EXPECT_EQ(it->second, v) << std::get<0>(key) << " t=" << std::get<1>(key);
    }
  }
  const std::size_t kept_total = committed.size();
  EXPECT_GT(kept_total, 0u) << "a kill landed before anything was committed; widen the window";

  station::Store clean(clean_db), killed(db);
  for (const char* serial : {"SIM-0001", "SIM-0002"}) {
    const auto a = clean.latest_fit(serial), b = killed.latest_fit(serial);
    ASSERT_TRUE(a && b) << serial;
    ASSERT_EQ(a->fit.coefficients.size(), b->fit.coefficients.size());
    for (std::size_t i = 0; i < a->fit.coefficients.size(); ++i) {
      EXPECT_DOUBLE_EQ(a->fit.coefficients[i], b->fit.coefficients[i])
          << serial << " " << a->fit.names[i];
    }
    EXPECT_EQ(a->fit.n_points, b->fit.n_points);
  }
}

TEST(KillResume, SigtermEndsTheRunCleanlyAsStopped) {
  const auto db = fresh_db("sigterm");
  const pid_t pid = spawn_run(db);
  // Wait (bounded) until the run has committed samples, then stop it mid-protocol.
  // (Read-only peeks: the test never creates the file under the daemon. The bound is generous:
  // a loaded machine may take seconds to start the process.)
  bool committed = false;
  for (int i = 0; i < 3000 && !committed; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    try {
      station::Store peek(db, station::OpenMode::read_only);
      committed = peek.find_run(1) && peek.sample_count(1) > 0;
    } catch (const station::SqliteError&) {  // not created or not migrated yet
    }
  }
  ASSERT_TRUE(committed) << "no sample committed within 30 s";
  kill(pid, SIGTERM);
  EXPECT_EQ(wait_exit(pid), 0);
  station::Store s(db);
  EXPECT_FALSE(s.find_unfinished_run().has_value()) << "a stopped run is not left 'running'";
  const auto run = s.find_run(1);
  ASSERT_TRUE(run.has_value());
  EXPECT_EQ(run->state, station::RunState::stopped);
  const auto events = s.events(1);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back(), "run_end: run 1 stopped");
  EXPECT_GT(s.sample_count(1), 0);
}
