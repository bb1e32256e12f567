// Issue 19 item 4: a full disk never leaves the store half-committed. A COMMIT that fails (EFBIG
// under RLIMIT_FSIZE here, as ENOSPC on a full disk) rolls back cleanly; once there is room again
// the same store writes on. Before the fix the batch stayed "open" after SQLite had rolled it
// back, and every later write failed with "cannot commit - no transaction is active".
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <csignal>
#include <string>
#include <vector>

#include "station/store/store.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using station::testing_support::fresh_db;

std::vector<station::SampleRow> rows_at(double t_s) {
  std::vector<station::SampleRow> rows;
  for (int g = 0; g < 16; ++g) {
    station::SampleRow r;
    r.serial = "G" + std::to_string(g);
    r.t_s = t_s;
    r.net_pulses = 1000 + g;
    r.rate_dph = 15.0 + g;
    r.temp_c = r.temp2_c = r.air_c = r.setpoint_c = 20.0;
    rows.push_back(r);
  }
  return rows;
}

std::vector<station::RunSlot> slots() {
  std::vector<station::RunSlot> out;
  for (int g = 0; g < 16; ++g) out.push_back({g, g + 1, "G" + std::to_string(g), "z", 1.0, 11.0});
  return out;
}

off_t size_of(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? st.st_size : 0;
}

/// Runs `f` with files limited to `max_bytes` (EFBIG beyond; SIGXFSZ ignored as the daemon does).
template <typename F>
void with_file_size_limit(rlim_t max_bytes, F f) {
  rlimit was{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &was), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = was;
  small.rlim_cur = max_bytes;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  f();
  setrlimit(RLIMIT_FSIZE, &was);
  std::signal(SIGXFSZ, old_handler);
}

}  // namespace

TEST(StoreFullDisk, AFailedCommitRollsBackAndTheStoreWritesOnOnceThereIsRoom) {
  const auto path = fresh_db("full-disk");
  station::Store s(path);
  const auto run = s.create_run(
      {"paper", "[[step]]", "[station]", "0.1.0", "rig", "alice", 42, 0.0, {}}, slots());
  s.set_ticks_per_commit(50);
  for (int t = 1; t <= 50; ++t) s.append_tick(run, t, rows_at(t), {});
  ASSERT_EQ(s.sample_count(run), 50 * 16);
  // The next batch of 50 ticks (800 samples, far beyond 8 KiB of pages) cannot be written.
  const auto limit = static_cast<rlim_t>(std::max(size_of(path), size_of(path + "-wal")) + 8192);
  std::string error;
  with_file_size_limit(limit, [&] {
    try {
      for (int t = 51; t <= 100; ++t) s.append_tick(run, t, rows_at(t), {});
      s.flush();
    } catch (const std::exception& e) {
      error = e.what();
    }
  });
  ASSERT_FALSE(error.empty()) << "the limit did not bite: nothing failed";
  EXPECT_FALSE(s.db().in_transaction()) << "a transaction was left open after: " << error;
  // Nothing of the failed batch is half there; everything committed before is.
  EXPECT_EQ(s.sample_count(run), 50 * 16) << error;
  // With room again the same store goes on: the lost ticks are written again, then events.
  for (int t = 51; t <= 100; ++t) s.append_tick(run, t, rows_at(t), {});
  EXPECT_NO_THROW(s.flush());
  EXPECT_NO_THROW(s.add_event(run, 100, station::Severity::error, "test",
                              station::EventKind::run_failed, "disk was full"));
  EXPECT_NO_THROW(s.finish_run(run, station::RunState::aborted));
  EXPECT_EQ(s.sample_count(run), 100 * 16);
  EXPECT_EQ(s.find_run(run)->state, station::RunState::aborted);
}
