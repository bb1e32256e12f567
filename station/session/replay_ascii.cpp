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
    : device_(std::move(device)), lines_(std::move(lines)) {}

bool RecordedLineWire::recorded_error(std::string_view what) {
  const SessionLogLine* l = peek();
  if (l == nullptr || l->direction != "event" || l->kind != "ascii-error" || l->bytes.size() != 4 ||
      l->detail.find(what) == std::string::npos)
    return false;
  ++next_;
  errno = drivers::errno_of_bytes(std::span<const std::uint8_t, 4>(l->bytes.data(), 4));
  return true;
}

int RecordedLineWire::open(double) {
  if (recorded_error(" connect ")) return -1;
  const SessionLogLine* l = peek();
  if (l == nullptr || l->direction != "event" || l->kind != "ascii-connect")
    throw ReplayDivergence(device_, l ? describe(*l) : "no more exchanges", "connect",
                           l ? l->t_s : 0);
  ++next_;
  return 0;
}

void RecordedLineWire::close() {
  const SessionLogLine* l = peek();
  if (l != nullptr && l->direction == "event" && l->kind == "ascii-disconnect") ++next_;
}

int RecordedLineWire::send(std::string_view bytes, double) {
  const SessionLogLine* l = peek();
  const auto sent = bytes_of(bytes);
  if (l == nullptr || l->direction != "tx" || l->kind != "ascii" || l->bytes != sent)
    throw ReplayDivergence(device_, l ? describe(*l) : "no more exchanges",
                           "tx ascii " + hex_field(sent), l ? l->t_s : 0);
  ++next_;
  if (recorded_error(" send '")) return -1;
  return static_cast<int>(bytes.size());
}

int RecordedLineWire::receive(std::string& line, std::string_view, double, std::size_t) {
  if (recorded_error(" reply to '")) return -1;
  const SessionLogLine* l = peek();
  if (l == nullptr || l->direction != "rx" || l->kind != "ascii")
    throw ReplayDivergence(device_, l ? describe(*l) : "no more exchanges", "the reply",
                           l ? l->t_s : 0);
  ++next_;
  line.assign(l->bytes.begin(), l->bytes.end());
  return static_cast<int>(line.size());
}

}  // namespace station
