// Issue 35: `station replay` printed the recorded run's warnings stamped with the current time, so
// a CI log read them as live. Each replayed line now says it is replayed and when it was
// recorded (session start + the tick's t); a progress line marks each tenth of the run. All on
// stderr: stdout (the verdict) and the comparison are unchanged.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <regex>
#include <sstream>

#include "station/session/replay_narration.hpp"
#include "tests/station/rig_process.hpp"

namespace {

namespace ts = station::testing_support;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

}  // namespace

TEST(ReplayNarration, RecordedTimeIsTheSessionStartPlusTheTick) {
  EXPECT_EQ(station::utc_plus("2026-11-27T23:33:28Z", 1500), "2026-11-27T23:58:28Z");
  EXPECT_EQ(station::utc_plus("2026-12-31T23:59:00Z", 61), "2027-01-01T00:00:01Z");
  EXPECT_THROW(station::utc_plus("2026-11-27 23:33:28", 0), std::runtime_error);
  // The form, but not a date and time: refused, not normalised into another day.
  EXPECT_THROW(station::utc_plus("2026-13-45T99:99:99Z", 0), std::runtime_error);
  EXPECT_THROW(station::utc_plus("2026--1--1T-1:-1:-1Z", 0), std::runtime_error);
  EXPECT_EQ(station::utc_plus("", 61.4), "at t = 61 s");
}

TEST(ReplayNarration, ReplayedWarningsCarryTheirRecordedTimeAndProgressIsShown) {
  // link_faults: a chamber outage at t = 1500 s of a run started 2026-11-27T23:33:28Z.
  const std::string dir = std::string(STATION_SOURCE_DIR) + "/tests/sessions/link_faults";
  const std::string base = ::testing::TempDir() + "narration-" + std::to_string(getpid());
  const int rc = std::system(
      (ts::kStationBin + " replay " + dir + " >" + base + ".out 2>" + base + ".err").c_str());
  ASSERT_TRUE(WIFEXITED(rc) && WEXITSTATUS(rc) == 0) << ts::slurp(base + ".out");
  EXPECT_NE(ts::slurp(base + ".out").find(": same ("), std::string::npos);
  const auto err = lines_of(ts::slurp(base + ".err"));
  const std::regex replayed(R"(^replayed, recorded 2026-11-2[78]T\d\d:\d\d:\d\dZ \w+ \[\w+\] .*)");
  const std::regex progress(R"(^replay: +\d+ % \(t = \d+ of 3402 s of the recorded run\)$)");
  int warnings = 0, progress_lines = 0;
  for (const auto& l : err) {
    if (std::regex_match(l, progress)) {
      ++progress_lines;
      continue;
    }
    EXPECT_TRUE(std::regex_match(l, replayed)) << "a line not marked replayed: " << l;
    ++warnings;
    if (l.find("outage_start t_s=1500 ") != std::string::npos)
      EXPECT_EQ(l.rfind("replayed, recorded 2026-11-27T23:58:28Z warning [chamber] ", 0), 0u) << l;
  }
  EXPECT_GE(warnings, 2);
  EXPECT_EQ(progress_lines, 10);
  EXPECT_NE(
      std::find(err.begin(), err.end(), "replay: 100 % (t = 3402 of 3402 s of the recorded run)"),
      err.end());
}

// A session whose started_utc is malformed still replays: the narration says so once and the
// lines carry the run time (hostile review, issue 35: 'yesterday' aborted the whole replay).
TEST(ReplayNarration, AMalformedStartIsSaidOnceAndTheReplayGoesOn) {
  std::FILE* progress = std::tmpfile();
  ASSERT_NE(progress, nullptr);
  {
    station::ReplayNarration n("yesterday", 100.0, progress);
    n.at(50.0);
  }
  std::rewind(progress);
  std::string text(4096, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), progress));
  std::fclose(progress);
  EXPECT_NE(text.find("replay: the session's started_utc 'yesterday': not YYYY-MM-DDTHH:MM:SSZ"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("replay:  50 %"), std::string::npos) << text;
}
