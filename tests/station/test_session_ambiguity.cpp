// Issue 36's hostile review, sessions: a file both plain and gzip'd is refused before anything is
// read (which one the run wrote cannot be told, and a check of one would vouch for the other),
// and a digest whose line count was edited is named by its line.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "station/common/input_error.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_replay.hpp"
#include "tests/station/temp_db.hpp"

namespace fs = std::filesystem;

namespace {

// A fresh copy of the shipped happy_cycle session (every log gzip'd, session.toml plain).
fs::path copy_session(const std::string& name) {
  const fs::path c = station::testing_support::fresh_db(name) + ".session";
  fs::remove_all(c);
  fs::copy(fs::path(STATION_SOURCE_DIR) / "tests/sessions/happy_cycle", c,
           fs::copy_options::recursive);
  return c;
}

std::string replay_error(const fs::path& dir) {
  try {
    station::replay_session({dir.string(), "", 0, 0, true});
  } catch (const station::InputError& e) {
    return e.what();
  }
  return "";
}

int sh(const std::string& cmd) {
  return std::system(cmd.c_str());
}

}  // namespace

TEST(SessionAmbiguity, AFileThereBothPlainAndGzippedIsRefusedNamingBoth) {
  const fs::path c = copy_session("ambiguous_log");
  ASSERT_EQ(sh("gzip -dk " + (c / "can.log.gz").string()), 0);  // can.log beside can.log.gz
  const std::string e = replay_error(c);
  EXPECT_NE(
      e.find((c / "can.log").string() + " and " + (c / "can.log.gz").string() + " both exist"),
      std::string::npos)
      << e;
  // The resolver itself: one of them is read, the other refused; neither: the plain name.
  EXPECT_THROW(station::session_file((c / "can.log").string()), station::InputError);
  EXPECT_EQ(station::session_file((c / "gpio.log").string()), (c / "gpio.log.gz").string());
  EXPECT_EQ(station::session_file((c / "none.log").string()), (c / "none.log").string());
  // The digest too (digest.txt and digest.txt.gz).
  const fs::path d = copy_session("ambiguous_digest");
  ASSERT_EQ(sh("gzip -dk " + (d / "digest.txt.gz").string()), 0);
  EXPECT_NE(replay_error(d).find("digest.txt.gz both exist"), std::string::npos) << replay_error(d);
  // Either one alone replays (the copy as shipped: the control that each check can fail).
  const fs::path ok = copy_session("unambiguous");
  EXPECT_EQ(replay_error(ok), "");
}

// The `file can.log N SHA` line's N edited: its tags no longer count N lines. The error names the
// digest's line (3: after the two comment lines), not only the file.
TEST(SessionAmbiguity, ADigestWhoseLineCountWasEditedNamesTheLine) {
  const fs::path c = copy_session("digest_count");
  ASSERT_EQ(sh("gzip -d " + (c / "digest.txt.gz").string()), 0);
  std::stringstream text;
  text << std::ifstream(c / "digest.txt").rdbuf();
  std::string s = text.str();
  const auto at = s.find("file can.log ");
  ASSERT_NE(at, std::string::npos);
  const auto n_at = at + std::string("file can.log ").size();
  const auto n_end = s.find(' ', n_at);
  const long n = std::stol(s.substr(n_at, n_end - n_at));
  s.replace(n_at, n_end - n_at, std::to_string(n + 1));
  std::ofstream(c / "digest.txt", std::ios::trunc) << s;
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += s[i] == '\n';
  const std::string e = replay_error(c);
  EXPECT_NE(e.find((c / "digest.txt").string() + ":" + std::to_string(line) + ": can.log has " +
                   std::to_string(n + 1) + " lines but " + std::to_string(n) + " tags"),
            std::string::npos)
      << e;
}
