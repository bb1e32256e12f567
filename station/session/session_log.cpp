// Session log lines: split, hex-decode; files read through zlib (plain or .gz alike).
#include "station/session/session_log.hpp"

#include <fmt/format.h>
#include <zlib.h>

#include <charconv>
#include <filesystem>
#include <memory>

#include "station/common/input_error.hpp"

namespace station {
namespace {

namespace dr = station::drivers;

dr::Error malformed(const std::string& what) {
  return dr::make_error(dr::ErrorKind::protocol, what);
}

// Next space-separated field of `rest` (advanced past it); empty at the end.
std::string_view next_field(std::string_view& rest) {
  const auto start = rest.find_first_not_of(' ');
  if (start == std::string_view::npos) {
    rest = {};
    return {};
  }
  rest.remove_prefix(start);
  const auto end = rest.find(' ');
  const auto field = rest.substr(0, end);
  rest.remove_prefix(end == std::string_view::npos ? rest.size() : end);
  return field;
}

bool decode_hex(std::string_view hex, std::vector<std::uint8_t>& out) {
  if (hex == "-") return true;
  if (hex.size() % 2 != 0) return false;
  for (std::size_t i = 0; i < hex.size(); i += 2) {
    std::uint8_t b = 0;
    const auto r = std::from_chars(hex.data() + i, hex.data() + i + 2, b, 16);
    if (r.ec != std::errc() || r.ptr != hex.data() + i + 2) return false;
    out.push_back(b);
  }
  return true;
}

struct GzClose {
  void operator()(gzFile f) const noexcept { gzclose(f); }
};
using GzHandle = std::unique_ptr<std::remove_pointer_t<gzFile>, GzClose>;

}  // namespace

dr::Result<SessionLogLine> parse_session_line(std::string_view line) {
  SessionLogLine out;
  std::string_view rest = line;
  const auto time = next_field(rest);
  const auto r = std::from_chars(time.data(), time.data() + time.size(), out.t_s);
  if (time.empty() || r.ec != std::errc() || r.ptr != time.data() + time.size())
    return malformed(fmt::format("bad time '{}'", time));
  out.device = next_field(rest);
  out.direction = next_field(rest);
  out.kind = next_field(rest);
  if (out.direction != "tx" && out.direction != "rx" && out.direction != "event")
    return malformed(fmt::format("bad direction '{}' (tx, rx or event)", out.direction));
  if (out.device.empty() || out.kind.empty()) return malformed("missing device or kind");
  const auto hex = next_field(rest);
  if (hex.empty() || !decode_hex(hex, out.bytes))
    return malformed(fmt::format("bad hex bytes '{}'", hex));
  if (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
  out.detail = rest;
  return out;
}

std::string for_each_line(const std::string& path,
                          const std::function<void(const std::string&, int)>& each) {
  std::string file = path;
  if (!std::filesystem::exists(file) && std::filesystem::exists(path + ".gz")) file = path + ".gz";
  // zlib reads a file that is not gzip-compressed as it is.
  GzHandle in(gzopen(file.c_str(), "rb"));
  if (!in) throw InputError(fmt::format("{}: cannot open the session log", file));
  std::string line;
  char buf[4096];
  int line_no = 0;
  const auto take = [&] {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) each(line, line_no);
  };
  while (gzgets(in.get(), buf, sizeof buf) != nullptr) {
    line += buf;
    if (line.back() != '\n') continue;  // a line longer than the buffer: read on
    line.pop_back();
    take();
    line.clear();
  }
  int err = Z_OK;
  gzerror(in.get(), &err);
  if (err != Z_OK && err != Z_STREAM_END)
    throw InputError(fmt::format("{}:{}: corrupt compressed data", file, line_no + 1));
  if (!line.empty()) take();
  return file;
}

std::vector<SessionLogLine> read_session_log(const std::string& path) {
  std::vector<SessionLogLine> out;
  std::string file = path;
  file = for_each_line(path, [&](const std::string& line, int line_no) {
    auto parsed = parse_session_line(line);
    if (!parsed) {
      const bool gz = !std::filesystem::exists(path);
      throw InputError(
          fmt::format("{}{}:{}: {}", path, gz ? ".gz" : "", line_no, parsed.error().message));
    }
    parsed.value().line_no = line_no;
    out.push_back(std::move(parsed).value());
  });
  return out;
}

std::vector<drivers::can::CandumpRecord> read_session_can_log(const std::string& path) {
  std::vector<drivers::can::CandumpRecord> out;
  for_each_line(path, [&](const std::string& line, int line_no) {
    if (line.find_first_not_of(" \t") == std::string::npos) return;
    auto r = drivers::can::parse_candump_line(line);
    if (!r) {
      const bool gz = !std::filesystem::exists(path);
      throw InputError(
          fmt::format("{}{}:{}: {}", path, gz ? ".gz" : "", line_no, r.error().message));
    }
    out.push_back(std::move(r).value());
  });
  return out;
}

}  // namespace station
