// Session log lines: split, hex-decode; files read plain or gzip'd alike (DecompressedReader).
#include "station/session/session_log.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <memory>

#include "station/common/input_error.hpp"
#include "station/session/session_files.hpp"

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

LogLineReader::LogLineReader(const std::string& path) : file_(session_file(path)) {
  try {
    in_ = std::make_unique<DecompressedReader>(file_);
  } catch (const InputError&) {
    throw InputError(fmt::format("{}: cannot open the session log", file_));
  }
}

LogLineReader::~LogLineReader() = default;

bool LogLineReader::refill() {
  buf_.erase(0, begin_);
  begin_ = 0;
  std::string_view bytes;
  try {
    bytes = in_->next();
  } catch (const CompressedDataError& e) {
    eof_ = true;
    if (digest_ != nullptr) digest_->corrupt(e.what());
    throw InputError(fmt::format("{}:{}: {}", file_, line_no_ + 1, e.what()));
  }
  if (digest_ != nullptr) digest_->add(bytes);
  buf_.append(bytes);
  eof_ = bytes.empty();
  return !eof_;
}

bool LogLineReader::next(std::string_view& line, int& line_no) {
  for (;;) {
    const auto nl = buf_.find('\n', begin_);
    if (nl == std::string::npos && !eof_ && refill()) continue;
    if (begin_ >= buf_.size()) return false;  // the end (a last line without newline taken)
    const auto end = nl == std::string::npos ? buf_.size() : nl;
    line = std::string_view(buf_).substr(begin_, end - begin_);
    begin_ = nl == std::string::npos ? buf_.size() : nl + 1;
    ++line_no_;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) continue;
    line_no = line_no_;
    return true;
  }
}

std::string for_each_line(const std::string& path,
                          const std::function<void(std::string_view, int)>& each) {
  LogLineReader reader(path);
  std::string_view line;
  int line_no = 0;
  while (reader.next(line, line_no)) each(line, line_no);
  return reader.file();
}

const SessionLogLine* SessionLogStream::peek() {
  if (next_) return &*next_;
  std::string_view line;
  int line_no = 0;
  if (!reader_.next(line, line_no)) return nullptr;
  auto parsed = parse_session_line(line);
  if (!parsed)
    throw InputError(fmt::format("{}:{}: {}", reader_.file(), line_no, parsed.error().message));
  parsed.value().line_no = line_no;
  next_ = std::move(parsed).value();
  return &*next_;
}

SessionLogLine SessionLogStream::take() {
  SessionLogLine out = std::move(*next_);
  next_.reset();
  return out;
}

bool CanLogStream::next(drivers::can::CandumpRecord& record) {
  std::string_view line;
  int line_no = 0;
  while (reader_.next(line, line_no)) {
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    auto r = drivers::can::parse_candump_line(line);
    if (!r) throw InputError(fmt::format("{}:{}: {}", reader_.file(), line_no, r.error().message));
    record = std::move(r).value();
    return true;
  }
  return false;
}

void read_session_log(const std::string& path, const std::function<void(SessionLogLine&&)>& each) {
  SessionLogStream stream(path);
  while (stream.peek() != nullptr) each(stream.take());
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
  CanLogStream stream(path);
  for (drivers::can::CandumpRecord r; stream.next(r);) out.push_back(std::move(r));
  return out;
}

}  // namespace station
