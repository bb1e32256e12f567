// Session log lines: split, hex-decode; files read through zlib (plain or .gz alike).
#include "station/session/session_log.hpp"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
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
                          const std::function<void(std::string_view, int)>& each) {
  std::string file = path;
  if (!std::filesystem::exists(file) && std::filesystem::exists(path + ".gz")) file = path + ".gz";
  // zlib reads a file that is not gzip-compressed as it is.
  GzHandle in(gzopen(file.c_str(), "rb"));
  if (!in) throw InputError(fmt::format("{}: cannot open the session log", file));
  // Large reads, lines split in place: a session log has millions of lines (a small file gets a
  // small buffer).
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  const std::size_t kChunk =
      ec ? std::size_t{1} << 20 : std::clamp<std::size_t>(size + 1, 4096, std::size_t{1} << 20);
  gzbuffer(in.get(), static_cast<unsigned>(kChunk));
  std::string buf;
  std::size_t begin = 0;  // first byte of buf not yet handed out
  int line_no = 0;
  const auto take = [&](std::string_view line) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (!line.empty()) each(line, line_no);
  };
  for (;;) {
    buf.erase(0, begin);
    begin = 0;
    const std::size_t had = buf.size();
    buf.resize(had + kChunk);
    const int n = gzread(in.get(), buf.data() + had, static_cast<unsigned>(kChunk));
    buf.resize(had + static_cast<std::size_t>(std::max(n, 0)));
    if (n <= 0) break;
    for (std::size_t nl; (nl = buf.find('\n', begin)) != std::string::npos; begin = nl + 1)
      take(std::string_view(buf).substr(begin, nl - begin));
  }
  int err = Z_OK;
  gzerror(in.get(), &err);
  if (err != Z_OK && err != Z_STREAM_END)
    throw InputError(fmt::format("{}:{}: corrupt compressed data", file, line_no + 1));
  if (begin < buf.size()) take(std::string_view(buf).substr(begin));
  return file;
}

void read_session_log(const std::string& path, const std::function<void(SessionLogLine&&)>& each) {
  const std::string file = for_each_line(path, [&](std::string_view line, int line_no) {
    auto parsed = parse_session_line(line);
    if (!parsed) {
      const bool gz = !std::filesystem::exists(path);
      throw InputError(
          fmt::format("{}{}:{}: {}", path, gz ? ".gz" : "", line_no, parsed.error().message));
    }
    parsed.value().line_no = line_no;
    each(std::move(parsed).value());
  });
}

namespace {

// A guess at a log's line count from its size (plain files only; a .gz is not sized), so the
// record vectors of a long session do not grow by copying millions of records.
std::size_t expected_lines(const std::string& path, std::size_t bytes_per_line) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  return ec ? 0 : static_cast<std::size_t>(size / bytes_per_line) + 16;
}

}  // namespace

std::vector<SessionLogLine> read_session_log(const std::string& path) {
  std::vector<SessionLogLine> out;
  out.reserve(expected_lines(path, 60));
  read_session_log(path, [&out](SessionLogLine&& l) { out.push_back(std::move(l)); });
  return out;
}

std::vector<drivers::can::CandumpRecord> read_session_can_log(const std::string& path) {
  std::vector<drivers::can::CandumpRecord> out;
  out.reserve(expected_lines(path, 40));
  for_each_line(path, [&](std::string_view line, int line_no) {
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
