// candump -l log format: writer/reader round trip, malformed lines, interop with can-utils
// log2long.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "drivers/can/candump_log.hpp"
#include "drivers/counters/counter_frames.hpp"

using namespace station::drivers;
namespace c = station::drivers::counters;

namespace {

can::CandumpRecord rec(std::int64_t s, std::uint32_t us, const can_frame& f) {
  return can::CandumpRecord{s, us, "can0", f};
}

std::vector<can::CandumpRecord> sample() {
  can_frame ext{};
  ext.can_id = 0x1ABCDEF0 | CAN_EFF_FLAG;
  ext.can_dlc = 4;
  std::memcpy(ext.data, "\xDE\xAD\xBE\xEF", 4);
  can_frame rtr{};
  rtr.can_id = 0x123 | CAN_RTR_FLAG;
  rtr.can_dlc = 3;
  return {rec(1700000000, 123456, c::encode(c::SyncFrame{5})),
          rec(1700000000, 123789, c::encode(c::CountsFrame{1, 0xFFFFFFF0u, 0x00000010u})),
          rec(1700000000, 124000, c::encode(c::TempsFrame{1, 2, {-4000, 2512}})),
          rec(1700000001, 5, ext), rec(1700000001, 999999, rtr)};
}

std::string temp_path(const char* name) {
  return (std::filesystem::temp_directory_path() /
          (std::string(name) + "_" + std::to_string(::getpid()) + ".log"))
      .string();
}

void expect_same(const can::CandumpRecord& a, const can::CandumpRecord& b) {
  EXPECT_EQ(a.time_sec, b.time_sec);
  EXPECT_EQ(a.time_usec, b.time_usec);
  EXPECT_EQ(a.interface, b.interface);
  EXPECT_EQ(a.frame.can_id, b.frame.can_id);
  ASSERT_EQ(a.frame.can_dlc, b.frame.can_dlc);
  if (!(a.frame.can_id & CAN_RTR_FLAG)) {
    EXPECT_EQ(std::memcmp(a.frame.data, b.frame.data, a.frame.can_dlc), 0);
  }
}

}  // namespace

TEST(CandumpLog, FormatsLikeCandump) {
  const auto s = sample();
  EXPECT_EQ(can::format_candump_line(s[0]), "(1700000000.123456) can0 080#05");
  EXPECT_EQ(can::format_candump_line(s[1]), "(1700000000.123789) can0 281#F0FFFFFF10000000");
  EXPECT_EQ(can::format_candump_line(s[3]), "(1700000001.000005) can0 1ABCDEF0#DEADBEEF");
  EXPECT_EQ(can::format_candump_line(s[4]), "(1700000001.999999) can0 123#R3");
}

TEST(CandumpLog, FileRoundTrip) {
  const std::string path = temp_path("candump_rt");
  const auto s = sample();
  can::write_candump_log(path, s);
  const auto back = can::read_candump_log(path);
  ASSERT_EQ(back.size(), s.size());
  for (std::size_t i = 0; i < s.size(); ++i) expect_same(back[i], s[i]);
  std::filesystem::remove(path);
}

TEST(CandumpLog, ParsesLowercaseDotsAndDirectionFlag) {
  auto r = can::parse_candump_line("(1.000001) vcan0 2a1#de.ad.be.ef T");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r.value().frame.can_id, 0x2A1u);
  EXPECT_EQ(r.value().frame.can_dlc, 4);
  EXPECT_EQ(r.value().frame.data[3], 0xEF);
}

TEST(CandumpLog, MalformedLinesSayWhat) {
  const std::pair<const char*, const char*> cases[] = {
      {"1700000000.123456 can0 080#05", "timestamp"},
      {"(1700000000.12345) can0 080#05", "6 decimals"},
      {"(1700000000.123456) can0 0800#05", "ID must be"},
      {"(1700000000.123456) can0 080#0", "hex byte pairs"},
      {"(1700000000.123456) can0 080#000102030405060708", "more than 8"},
      {"(1700000000.123456) can0 080-05", "missing '#'"},
      {"(1700000000.123456) can0 080##105", "CAN FD"},
      {"(1700000000.123456) can0", "expected"},
      {"(1700000000.123456) can0 800#05", "above 0x7FF"},
  };
  for (const auto& [line, what] : cases) {
    auto r = can::parse_candump_line(line);
    ASSERT_FALSE(r.ok()) << line;
    EXPECT_EQ(r.error().kind, ErrorKind::protocol);
    EXPECT_NE(r.error().message.find(what), std::string::npos)
        << line << " -> " << r.error().message;
  }
}

TEST(CandumpLog, ReaderNamesFileAndLine) {
  const std::string path = temp_path("candump_bad");
  {
    std::ofstream out(path);
    out << "(1700000000.123456) can0 080#05\n\n(1700000000.223456) can0 281#XYZ\n";
  }
  try {
    can::read_candump_log(path);
    FAIL() << "expected a parse error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3:"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(CandumpLog, TapWritesFramesItSees) {
  std::ostringstream out;
  can::CandumpTap tap(out, "can1");
  TapRecord r;
  r.wall_time_s = 1700000000.5;
  r.kind = "can";
  const can_frame f = c::encode(c::SyncFrame{7});
  r.bytes.assign(reinterpret_cast<const std::uint8_t*>(&f),
                 reinterpret_cast<const std::uint8_t*>(&f) + sizeof f);
  tap.on_exchange(r);
  r.kind = "error";
  tap.on_exchange(r);
  EXPECT_EQ(out.str(), "(1700000000.500000) can1 080#07\n");
}

// can-utils' own parser (log2long) must read what we write.
TEST(CandumpLog, Log2LongReadsOurLog) {
  if (::access("/usr/bin/log2long", X_OK) != 0) GTEST_SKIP() << "can-utils log2long not installed";
  const std::string path = temp_path("candump_l2l");
  const auto s = sample();
  can::write_candump_log(path, s);
  FILE* p = ::popen(("/usr/bin/log2long < " + path).c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::vector<std::string> lines;
  std::array<char, 512> buf{};
  while (std::fgets(buf.data(), buf.size(), p)) lines.emplace_back(buf.data());
  ASSERT_EQ(::pclose(p), 0);
  std::filesystem::remove(path);
  ASSERT_EQ(lines.size(), s.size());
  // Long format: "(TIME)  IFACE  ID   [DLC]  B0 B1 ...   'ascii'" or "remote request".
  for (std::size_t i = 0; i < s.size(); ++i) {
    std::istringstream in(lines[i]);
    std::string time, iface, id, dlc;
    in >> time >> iface >> id >> dlc;
    EXPECT_EQ(iface, "can0");
    EXPECT_EQ(std::stoul(id, nullptr, 16), s[i].frame.can_id & CAN_EFF_MASK) << lines[i];
    EXPECT_EQ(dlc, "[" + std::to_string(s[i].frame.can_dlc) + "]") << lines[i];
    if (s[i].frame.can_id & CAN_RTR_FLAG) {
      EXPECT_NE(lines[i].find("remote request"), std::string::npos);
      continue;
    }
    for (int k = 0; k < s[i].frame.can_dlc; ++k) {
      std::string byte;
      in >> byte;
      EXPECT_EQ(std::stoul(byte, nullptr, 16), s[i].frame.data[k]) << lines[i] << " byte " << k;
    }
  }
}
