// A batch of ticks commits its samples and the run's progress (written once, by the commit) in one
// transaction: a daemon killed between two ticks of one batch leaves the progress of the last
// committed tick and exactly that tick's samples, and a resume from there stores what an
// uninterrupted run stores.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <map>
#include <string>

#include "station/store/store.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using station::testing_support::fresh_db;

constexpr int kTicksPerCommit = 60;
const std::vector<std::string> kSerials{"SN1", "SN2", "SN3"};

station::RunInfo info() {
  station::RunInfo i;
  i.protocol_name = "batch";
  i.protocol_text = "[[step]]";
  i.config_text = "{}";
  i.software_version = "test";
  i.station = "bench";
  return i;
}

// Tick t's progress: a new step every 7 ticks, recording from tick 20, so consecutive batches
// end on different steps (a stale progress row would show).
station::RunProgress progress_at(int t) {
  station::RunProgress p;
  p.step_index = t / 7;
  p.step_started_s = 7.0 * (t / 7);
  p.recording = t >= 20;
  if (p.recording) p.record_start_s = 20.0;
  p.start_temp_c = 25.5;
  return p;
}

std::vector<station::SampleRow> rows_at(int t) {
  std::vector<station::SampleRow> out;
  for (std::size_t i = 0; i < kSerials.size(); ++i) {
    station::SampleRow r;
    r.serial = kSerials[i];
    r.t_s = t;
    r.net_pulses = 1000 * t + static_cast<std::int64_t>(i);
    r.rate_dph = 0.25 * t + static_cast<double>(i);
    r.temp_c = 20.0 + 0.01 * t;
    r.recording = t >= 20;
    out.push_back(r);
  }
  return out;
}

void append(station::Store& s, std::int64_t run, int from, int to) {
  for (int t = from; t < to; ++t) s.append_tick(run, t, rows_at(t), progress_at(t));
}

std::int64_t new_run(const std::string& db) {
  station::Store s(db);
  std::vector<station::RunSlot> slots;
  for (std::size_t i = 0; i < kSerials.size(); ++i)
    slots.push_back({static_cast<int>(i), static_cast<int>(i + 1), kSerials[i], "up", 1.5, 9.6});
  return s.create_run(info(), slots);
}

using Samples = std::map<std::pair<std::string, double>, std::pair<std::int64_t, double>>;

Samples samples_of(station::Store& s, std::int64_t run) {
  Samples out;
  for (const auto& serial : kSerials)
    for (const auto& r : s.samples(run, serial, false))
      out[{serial, r.t_s}] = {r.net_pulses.value_or(-1), r.rate_dph.value_or(-1)};
  return out;
}

// The run's fleet_outbox row: its `changes` (bumped by migration 7's triggers) and samples_done.
std::pair<std::int64_t, std::int64_t> outbox_of(station::Store& s, std::int64_t run) {
  auto st = s.db().prepare(
      "SELECT changes, samples_done FROM fleet_outbox WHERE item = 'run' AND local_id = ?");
  st.bind(1, run);
  if (!st.step()) return {-1, -1};
  return {st.column_int(0), st.column_int(1)};
}

// In a child process: ticks 0 .. kill_before_t - 1 appended, then SIGKILL (no flush, no unwind).
void killed_writer(const std::string& db, std::int64_t run, int kill_before_t) {
  const pid_t pid = fork();
  ASSERT_NE(pid, -1);
  if (pid == 0) {
    station::Store s(db, station::OpenMode::existing);
    s.set_ticks_per_commit(kTicksPerCommit);
    append(s, run, 0, kill_before_t);
    raise(SIGKILL);
    _exit(0);  // not reached
  }
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
}

}  // namespace

TEST(StoreBatchKill, AKillBetweenTwoTicksOfOneBatchLeavesTheLastCommittedTicksProgress) {
  const auto clean_db = fresh_db("batch-clean");
  const auto clean_run = new_run(clean_db);
  {
    station::Store s(clean_db, station::OpenMode::existing);
    s.set_ticks_per_commit(kTicksPerCommit);
    append(s, clean_run, 0, 200);
  }
  // Killed after tick 140: batches [0, 60) and [60, 120) committed, 20 ticks of the third not;
  // tick 119's progress (step 17 since 119 s, recording) differs from tick 139's (step 19).
  const auto db = fresh_db("batch-killed");
  const auto run = new_run(db);
  std::int64_t changes_at_start = 0;
  {
    station::Store s(db, station::OpenMode::existing);
    s.db().exec("UPDATE fleet_outbox SET samples_done = 1");  // as after a forward
    changes_at_start = outbox_of(s, run).first;
  }
  killed_writer(db, run, 140);
  {
    station::Store s(db, station::OpenMode::existing);
    const auto rec = s.find_unfinished_run();
    ASSERT_TRUE(rec);
    ASSERT_TRUE(rec->last_tick_s);
    EXPECT_EQ(*rec->last_tick_s, 119.0);
    EXPECT_EQ(rec->progress.step_index, progress_at(119).step_index);
    EXPECT_EQ(rec->progress.step_started_s, progress_at(119).step_started_s);
    EXPECT_TRUE(rec->progress.recording);
    EXPECT_EQ(rec->progress.record_start_s, 20.0);
    EXPECT_EQ(rec->progress.start_temp_c, 25.5);
    auto max_t = s.db().prepare("SELECT max(t_s), count(*) FROM samples WHERE run_id = ?");
    max_t.bind(1, run);
    ASSERT_TRUE(max_t.step());
    EXPECT_EQ(max_t.column_double(0), 119.0) << "samples beyond the committed progress";
    EXPECT_EQ(max_t.column_int(1), 120 * static_cast<std::int64_t>(kSerials.size()));
    // The fleet outbox saw the run change with each committed batch (migration 7's trigger),
    // and wants its samples sent again.
    const auto [changes, samples_done] = outbox_of(s, run);
    EXPECT_EQ(changes, changes_at_start + 2) << "one change per committed batch";
    EXPECT_EQ(samples_done, 0);
  }
  // Resumed from the next tick: the same samples and the same end as the uninterrupted run.
  {
    station::Store s(db, station::OpenMode::existing);
    s.set_ticks_per_commit(kTicksPerCommit);
    append(s, run, 120, 200);
  }
  station::Store clean(clean_db, station::OpenMode::existing),
      killed(db, station::OpenMode::existing);
  EXPECT_EQ(samples_of(killed, run), samples_of(clean, clean_run));
  const auto a = clean.find_run(clean_run), b = killed.find_run(run);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->last_tick_s, b->last_tick_s);
  EXPECT_EQ(b->last_tick_s, 199.0);
  EXPECT_EQ(a->progress.step_index, b->progress.step_index);
  EXPECT_EQ(a->progress.step_started_s, b->progress.step_started_s);
}

TEST(StoreBatchKill, AKillOnABatchBoundaryKeepsTheWholeBatchAndItsProgress) {
  const auto db = fresh_db("batch-boundary");
  const auto run = new_run(db);
  killed_writer(db, run, 2 * kTicksPerCommit);  // the second batch committed by its last tick
  station::Store s(db, station::OpenMode::existing);
  const auto rec = s.find_unfinished_run();
  ASSERT_TRUE(rec && rec->last_tick_s);
  EXPECT_EQ(*rec->last_tick_s, 2.0 * kTicksPerCommit - 1);
  EXPECT_EQ(rec->progress.step_index, progress_at(2 * kTicksPerCommit - 1).step_index);
  EXPECT_EQ(s.sample_count(run), 2 * kTicksPerCommit * static_cast<std::int64_t>(kSerials.size()));
}

TEST(StoreBatchKill, ADiscardedBatchTakesItsProgressWithIt) {
  // A failed tick (or replay's simulated kill) rolls the batch back: its progress is not written
  // by a later commit either.
  const auto db = fresh_db("batch-discard");
  const auto run = new_run(db);
  station::Store s(db, station::OpenMode::existing);
  s.set_ticks_per_commit(kTicksPerCommit);
  append(s, run, 0, 10);
  s.discard();
  s.flush();
  const auto rec = s.find_run(run);
  ASSERT_TRUE(rec);
  EXPECT_FALSE(rec->last_tick_s) << "the discarded batch's progress was committed";
  EXPECT_EQ(s.sample_count(run), 0);
  append(s, run, 0, 3);  // the same ticks again: nothing of the discarded batch is in the way
  s.flush();
  EXPECT_EQ(s.find_run(run)->last_tick_s, 2.0);
}
