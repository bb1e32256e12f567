// Issue 37, replay streamed: a session's logs are read a chunk at a time (LogLineReader over
// DecompressedReader), so a line may straddle any number of chunks; the digest taken as the replay
// reads a file (SessionReads) is the one digest_file takes on its own; and a replayed device's
// feed reads the log only as far as it is asked.
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "station/common/input_error.hpp"
#include "station/session/replay_feed.hpp"
#include "station/session/session_digest.hpp"
#include "station/session/session_log.hpp"

namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path d = ::testing::TempDir() + name + "-" + std::to_string(getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Lines of every awkward shape: empty, CRLF, one of 200,000 bytes (three 64 KiB chunks), no
// newline at the end.
std::string awkward_text() {
  std::string t = "first line\n\nsecond\r\n";
  for (int i = 0; i < 5000; ++i)
    t += "line " + std::to_string(i) + " " + std::string(i % 97, 'x') + "\n";
  t += std::string(200000, 'y') + "\n";
  t += "\r\n";
  t += "last without newline";
  return t;
}

// What LogLineReader must give: the non-empty lines (a CR before the newline cut) and their
// 1-based numbers, counting the empty ones.
std::vector<std::pair<int, std::string>> expected_lines(const std::string& t) {
  std::vector<std::pair<int, std::string>> out;
  int no = 0;
  for (std::size_t begin = 0; begin < t.size();) {
    const auto nl = std::min(t.find('\n', begin), t.size());
    std::string line = t.substr(begin, nl - begin);
    begin = nl + 1;
    ++no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) out.emplace_back(no, line);
  }
  return out;
}

std::vector<std::pair<int, std::string>> read_all(station::LogLineReader& r) {
  std::vector<std::pair<int, std::string>> out;
  std::string_view line;
  int no = 0;
  while (r.next(line, no)) out.emplace_back(no, std::string(line));
  return out;
}

void write_gz(const fs::path& p, const std::string& t) {
  gzFile f = gzopen(p.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(gzwrite(f, t.data(), static_cast<unsigned>(t.size())), static_cast<int>(t.size()));
  gzclose(f);
}

}  // namespace

TEST(SessionStream, LinesStraddlingChunksReadTheSamePlainOrGzipped) {
  const auto dir = temp_dir("session_stream_lines");
  const std::string text = awkward_text();
  std::ofstream(dir / "plain.log", std::ios::binary) << text;
  write_gz(dir / "packed.log.gz", text);
  const auto want = expected_lines(text);
  ASSERT_EQ(want.size(), 5004u);
  station::LogLineReader plain((dir / "plain.log").string());
  EXPECT_EQ(read_all(plain), want);
  station::LogLineReader packed((dir / "packed.log").string());  // only the .gz exists
  EXPECT_EQ(packed.file(), (dir / "packed.log.gz").string());
  EXPECT_EQ(read_all(packed), want);
}

TEST(SessionStream, TheDigestTakenAsTheFileIsReadIsTheOneOfTheFileAlone) {
  const auto dir = temp_dir("session_stream_digest");
  const std::string text = awkward_text();
  std::ofstream(dir / "can.log", std::ios::binary) << text;
  write_gz(dir / "gpio.log.gz", text);
  for (const char* name : {"can.log", "gpio.log"}) {
    const station::FileDigest alone = station::digest_file(dir.string(), name);
    station::DigestBuilder streamed(name);
    station::LogLineReader r((dir / name).string());
    r.digest_into(&streamed);
    // Read part of the way, as a replay that diverged early, then on to the end.
    std::string_view line;
    int no = 0;
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(r.next(line, no));
    read_all(r);
    const station::FileDigest d = streamed.finish();
    EXPECT_EQ(d.lines, alone.lines) << name;
    EXPECT_EQ(d.sha256_hex, alone.sha256_hex) << name;
    EXPECT_EQ(d.tags, alone.tags) << name;
    EXPECT_EQ(d.lines, 5006) << name;  // every line, the empty ones and the last one included
  }
}

TEST(SessionStream, BytesAfterTheCompressedEndAreNamedByTheReader) {
  const auto dir = temp_dir("session_stream_garbage");
  write_gz(dir / "modbus.log.gz", "0.5 chamber event connect - \n");
  std::ofstream(dir / "modbus.log.gz", std::ios::binary | std::ios::app) << "not the run's";
  station::LogLineReader r((dir / "modbus.log").string());
  std::string_view line;
  int no = 0;
  ASSERT_TRUE(r.next(line, no));
  try {
    r.next(line, no);
    FAIL() << "no error";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("modbus.log.gz:2: bytes after the end"), std::string::npos)
        << e.what();
  }
}

TEST(SessionStream, AFeedReadsTheLogOnlyAsFarAsItIsAsked) {
  int pulled = 0;
  station::ReplayFeed<int> feed(
      {1, 2},
      [&pulled](int& v) {
        if (pulled == 100) return false;
        v = 10 + pulled++;
        return true;
      },
      false);
  EXPECT_EQ(*feed.peek(), 1);
  EXPECT_EQ(pulled, 0);  // the items given first, nothing read
  EXPECT_EQ(*feed.peek(3), 11);
  EXPECT_EQ(pulled, 2);
  EXPECT_EQ(feed.take(), 1);
  EXPECT_EQ(feed.take(), 2);
  EXPECT_EQ(feed.take(), 10);
  EXPECT_EQ(feed.read_ahead(), 1u);
  EXPECT_TRUE(feed.consumed().empty());  // not kept unless asked
  EXPECT_EQ(feed.remaining(), 99u);      // the rest of the log: 11 .. 109
  EXPECT_EQ(feed.peek(99), nullptr);
}
