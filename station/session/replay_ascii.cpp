// Answering a LineClient from a recording (see replay_ascii.hpp).
#include "station/session/replay_ascii.hpp"

#include <fmt/format.h>

#include <cerrno>

#include "drivers/common/tap.hpp"
#include "station/session/session_recorder.hpp"

namespace station {
namespace {

std::string describe(const SessionLogLine& l) {
  return fmt::format("line {}: {} {} {}", l.line_no, l.direction, l.kind, hex_field(l.bytes));
}

std::vector<std::uint8_t> bytes_of(std::string_view s) {
  return {s.begin(), s.end()};
}

}  // namespace

RecordedLineWire::RecordedLineWire(std::string device, std::vector<SessionLogLine> lines)
    : RecordedLineWire(std::move(device), ReplayFeed<SessionLogLine>(std::move(lines))) {}

RecordedLineWire::RecordedLineWire(std::string device, ReplayFeed<SessionLogLine> lines)
    : device_(std::move(device)), lines_(std::move(lines)) {}

bool RecordedLineWire::recorded_error(std::string_view what) {
  const SessionLogLine* l = peek();
  if (l == nullptr || l->direction != "event" || l->kind != "ascii-error" || l->bytes.size() != 4 ||
      l->detail.find(what) == std::string::npos)
    return false;
  const auto& e = lines_.take();
  errno = drivers::errno_of_bytes(std::span<const std::uint8_t, 4>(e.bytes.data(), 4));
  return true;
}

int RecordedLineWire::open(double) {
  if (recorded_error(" connect ")) return -1;
  const SessionLogLine* l = peek();
  if (l == nullptr || l->direction != "event" || l->kind != "ascii-connect")
    throw ReplayDivergence(device_, l ? describe(*l) : "no more exchanges", "connect",
                           l ? l->t_s : 0);
  (void)lines_.take();
  return 0;
}

void RecordedLineWire::close() {
  const SessionLogLine* l = peek();
  if (l != nullptr && l->direction == "event" && l->kind == "ascii-disconnect") (void)lines_.take();
}

int RecordedLineWire::send(std::string_view bytes, double) {
  reply_open_ = false;  // what was left unread is discarded, as the real link flushes it
  reply_.clear();
  const SessionLogLine* l = peek();
  const auto sent = bytes_of(bytes);
  if (l == nullptr || l->direction != "tx" || l->kind != "ascii" || l->bytes != sent)
    throw ReplayDivergence(device_, l ? describe(*l) : "no more exchanges",
                           "tx ascii " + hex_field(sent), l ? l->t_s : 0);
  (void)lines_.take();
  if (recorded_error(" send '")) return -1;
  return static_cast<int>(bytes.size());
}

bool RecordedLineWire::open_reply() {
  if (reply_open_) return true;
  if (recorded_error(" reply to '")) return false;
  const SessionLogLine* l = peek();
  if (l == nullptr || l->direction != "rx" || l->kind != "ascii")
    throw ReplayDivergence(device_, l ? describe(*l) : "no more exchanges", "the reply",
                           l ? l->t_s : 0);
  const auto& r = lines_.take();
  reply_.assign(r.bytes.begin(), r.bytes.end());
  reply_open_ = true;
  return true;
}

int RecordedLineWire::receive(std::string& line, std::string_view terminator, double, std::size_t) {
  if (!open_reply()) return -1;
  // A reply recorded with its terminator (read in parts) gives it back without.
  if (reply_.ends_with(terminator)) reply_.resize(reply_.size() - terminator.size());
  line = std::move(reply_);
  reply_.clear();
  reply_open_ = false;
  return static_cast<int>(line.size());
}

int RecordedLineWire::receive_exact(std::string& bytes, std::size_t n, double) {
  if (!open_reply()) return -1;
  if (reply_.size() < n) {
    const SessionLogLine* l = lines_.taken() > 0 ? &lines_.last() : nullptr;
    throw ReplayDivergence(device_, l ? describe(*l) : "no more exchanges",
                           fmt::format("{} more reply bytes", n), l ? l->t_s : 0);
  }
  bytes = reply_.substr(0, n);
  reply_.erase(0, n);
  reply_open_ = !reply_.empty();
  return static_cast<int>(n);
}

}  // namespace station
