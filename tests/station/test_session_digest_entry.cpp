// Issue 36's hostile review, sessions: a digest.txt whose `file NAME LINES SHA256` line was
// deleted names NAME's entry as what is missing, not the line that now stands in its place
// ("tags out of order" at the next line, or "not as the station writes digest.txt" there).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "station/common/input_error.hpp"
#include "station/session/session_digest.hpp"
#include "tests/station/temp_db.hpp"

namespace fs = std::filesystem;

namespace {

// A copy of the shipped happy_cycle session with digest.txt unzipped and its `file NAME` line
// deleted; in *line the line of NAME's first `tags` line after the deletion (0: none).
fs::path without_file_line(const std::string& test, const std::string& name, int* line) {
  const fs::path c = station::testing_support::fresh_db(test) + ".session";
  fs::remove_all(c);
  fs::copy(fs::path(STATION_SOURCE_DIR) / "tests/sessions/happy_cycle", c,
           fs::copy_options::recursive);
  EXPECT_EQ(std::system(("gzip -d " + (c / "digest.txt.gz").string()).c_str()), 0);
  std::stringstream text;
  text << std::ifstream(c / "digest.txt").rdbuf();
  std::string s = text.str();
  const auto at = s.find("\nfile " + name + " ");
  EXPECT_NE(at, std::string::npos) << name;
  s.erase(at + 1, s.find('\n', at + 1) - at);
  const auto tags = s.find("\ntags " + name + " ");
  *line = 0;
  if (tags != std::string::npos)
    *line = 2 + static_cast<int>(std::count(s.begin(), s.begin() + tags, '\n'));
  std::ofstream(c / "digest.txt", std::ios::trunc) << s;
  return c;
}

std::string verify_text(const fs::path& dir) {
  try {
    const auto m = station::verify_session_digest(dir.string());
    return m ? m->message() : "";
  } catch (const station::InputError& e) {
    return e.what();
  }
}

}  // namespace

// can.log's file line (its tags further down): named at its first tags line (read_digest said
// "tags out of order or not 4-digit hex" there, naming no file).
TEST(SessionDigestEntry, ADeletedFileLineBeforeItsTagsNamesTheFile) {
  int line = 0;
  const fs::path c = without_file_line("digest_no_can_line", "can.log", &line);
  const std::string e = verify_text(c);
  EXPECT_NE(e.find((c / "digest.txt").string() + ":" + std::to_string(line) +
                   ": tags of can.log with no 'file can.log LINES SHA256' line before them: "
                   "the digest's entry for can.log is missing"),
            std::string::npos)
      << e;
}

// ascii.log has no lines and so no tags: its file line deleted left a digest that reads, and
// the first difference from the one form was the next file's line. The file is named.
TEST(SessionDigestEntry, ADeletedFileLineOfAnEmptyFileNamesTheFile) {
  int line = 0;
  const fs::path c = without_file_line("digest_no_ascii_line", "ascii.log", &line);
  const std::string e = verify_text(c);
  EXPECT_NE(e.find("no 'file ascii.log' line: the digest's entry for ascii.log is missing, the "
                   "file is there"),
            std::string::npos)
      << e;
  EXPECT_EQ(e.find("not as the station writes"), std::string::npos) << e;
}

// The control: the copy as shipped verifies (each check above can fail only on its edit).
TEST(SessionDigestEntry, TheUneditedCopyVerifies) {
  const fs::path c = station::testing_support::fresh_db("digest_entry_control") + ".session";
  fs::remove_all(c);
  fs::copy(fs::path(STATION_SOURCE_DIR) / "tests/sessions/happy_cycle", c,
           fs::copy_options::recursive);
  EXPECT_EQ(verify_text(c), "");
}
