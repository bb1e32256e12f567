// candump -l log lines (can-utils lib.c sprint_canframe/parse_canframe format), file I/O, Tap.
#include "drivers/can/candump_log.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cstring>
#include <fstream>
#include <ostream>
#include <stdexcept>

namespace station::drivers::can {
namespace {

Error malformed(std::string_view what) {
  return make_error(ErrorKind::protocol, fmt::format("malformed candump line: {}", what));
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool parse_hex(std::string_view s, std::uint32_t& out) {
  out = 0;
  for (char c : s) {
    const int v = hex_value(c);
    if (v < 0) return false;
    out = out << 4 | static_cast<std::uint32_t>(v);
  }
  return !s.empty();
}

// "(1700000000.123456)" -> seconds and microseconds.
Result<void> parse_time(std::string_view tok, CandumpRecord& r) {
  if (tok.size() < 10 || tok.front() != '(' || tok.back() != ')')
    return malformed("timestamp must look like (SECONDS.MICROSECONDS)");
  const auto body = tok.substr(1, tok.size() - 2);
  const auto dot = body.find('.');
  if (dot == body.npos || body.size() - dot - 1 != 6)
    return malformed("timestamp needs 6 decimals");
  const char* b = body.data();
  auto [p1, e1] = std::from_chars(b, b + dot, r.time_sec);
  auto [p2, e2] = std::from_chars(b + dot + 1, b + body.size(), r.time_usec);
  if (e1 != std::errc{} || p1 != b + dot || e2 != std::errc{} || p2 != b + body.size())
    return malformed("timestamp is not numeric");
  return {};
}

Result<void> parse_id(std::string_view id, can_frame& f) {
  std::uint32_t v = 0;
  if ((id.size() != 3 && id.size() != 8) || !parse_hex(id, v))
    return malformed("ID must be 3 (standard) or 8 (extended) hex digits");
  if (id.size() == 3) {
    if (v > CAN_SFF_MASK) return malformed("standard ID above 0x7FF");
    f.can_id = v;
  } else if (v & CAN_ERR_FLAG) {
    f.can_id = v;  // error frame: the log carries the flag in the ID (can-utils convention)
  } else {
    if (v > CAN_EFF_MASK) return malformed("extended ID above 0x1FFFFFFF");
    f.can_id = v | CAN_EFF_FLAG;
  }
  return {};
}

Result<void> parse_data(std::string_view d, can_frame& f) {
  if (!d.empty() && d.front() == '#') return malformed("CAN FD frames (##) are not supported");
  if (!d.empty() && (d.front() == 'R' || d.front() == 'r')) {
    f.can_id |= CAN_RTR_FLAG;
    const int len = d.size() == 2 ? hex_value(d[1]) : 0;
    if (d.size() > 2 || len < 0 || len > CAN_MAX_DLEN) return malformed("bad remote frame length");
    f.can_dlc = static_cast<std::uint8_t>(len);
    return {};
  }
  std::size_t n = 0;
  for (std::size_t i = 0; i < d.size();) {
    if (d[i] == '.') {
      ++i;
      continue;
    }  // can-utils accepts dots between bytes
    const int hi = hex_value(d[i]);
    const int lo = i + 1 < d.size() ? hex_value(d[i + 1]) : -1;
    if (hi < 0 || lo < 0) return malformed("DATA must be hex byte pairs");
    if (n == CAN_MAX_DLEN) return malformed("more than 8 data bytes");
    f.data[n++] = static_cast<std::uint8_t>(hi << 4 | lo);
    i += 2;
  }
  f.can_dlc = static_cast<std::uint8_t>(n);
  return {};
}

}  // namespace

std::string format_candump_line(const CandumpRecord& r) {
  const can_frame& f = r.frame;
  std::string id = (f.can_id & (CAN_EFF_FLAG | CAN_ERR_FLAG))
                       ? fmt::format("{:08X}", f.can_id & (CAN_EFF_MASK | CAN_ERR_FLAG))
                       : fmt::format("{:03X}", f.can_id & CAN_SFF_MASK);
  std::string line = fmt::format("({}.{:06}) {} {}#", r.time_sec, r.time_usec, r.interface, id);
  const int len = f.can_dlc > CAN_MAX_DLEN ? CAN_MAX_DLEN : f.can_dlc;
  if (f.can_id & CAN_RTR_FLAG) {
    line += 'R';
    if (len > 0) line += static_cast<char>('0' + len);
    return line;
  }
  for (int i = 0; i < len; ++i) line += fmt::format("{:02X}", f.data[i]);
  return line;
}

Result<CandumpRecord> parse_candump_line(std::string_view line) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
  CandumpRecord r;
  std::memset(&r.frame, 0, sizeof r.frame);
  const auto s1 = line.find(' ');
  const auto s2 = s1 == line.npos ? line.npos : line.find(' ', s1 + 1);
  if (s2 == line.npos) return malformed("expected '(TIME) IFACE ID#DATA'");
  if (auto t = parse_time(line.substr(0, s1), r); !t) return t.error();
  r.interface = std::string(line.substr(s1 + 1, s2 - s1 - 1));
  if (r.interface.empty()) return malformed("empty interface name");
  std::string_view frame = line.substr(s2 + 1);
  if (const auto sp = frame.find(' '); sp != frame.npos) {
    const auto flag = frame.substr(sp + 1);  // newer candump appends a direction flag T or R
    if (flag != "T" && flag != "R") return malformed("unexpected text after the frame");
    frame = frame.substr(0, sp);
  }
  const auto hash = frame.find('#');
  if (hash == frame.npos) return malformed("missing '#' between ID and DATA");
  if (auto i = parse_id(frame.substr(0, hash), r.frame); !i) return i.error();
  if (auto d = parse_data(frame.substr(hash + 1), r.frame); !d) return d.error();
  return r;
}

void write_candump_log(const std::string& path, const std::vector<CandumpRecord>& records) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(fmt::format("{}: cannot open for writing", path));
  for (const auto& r : records) out << format_candump_line(r) << '\n';
  out.flush();
  if (!out) throw std::runtime_error(fmt::format("{}: write failed", path));
}

std::vector<CandumpRecord> read_candump_log(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open for reading", path));
  std::vector<CandumpRecord> out;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    auto r = parse_candump_line(line);
    if (!r) throw std::runtime_error(fmt::format("{}:{}: {}", path, n, r.error().message));
    out.push_back(std::move(r).value());
  }
  return out;
}

CandumpTap::CandumpTap(std::ostream& out, std::string interface, std::function<double()> now_s)
    : out_(out), interface_(std::move(interface)), now_s_(std::move(now_s)) {}

void CandumpTap::on_exchange(const TapRecord& record) noexcept {
  if (record.kind != "can" || record.bytes.size() != sizeof(can_frame)) return;
  try {
    CandumpRecord r;
    std::memcpy(&r.frame, record.bytes.data(), sizeof r.frame);
    const double sec = now_s_ ? now_s_() : record.wall_time_s;
    r.time_sec = static_cast<std::int64_t>(sec);
    r.time_usec = static_cast<std::uint32_t>((sec - static_cast<double>(r.time_sec)) * 1e6);
    if (r.time_usec > 999999) r.time_usec = 999999;
    r.interface = interface_;
    const std::lock_guard lock(mutex_);
    out_ << format_candump_line(r) << '\n';
  } catch (...) {
    // A tap must never throw into the transport; a lost log line is preferable.
  }
}

}  // namespace station::drivers::can
