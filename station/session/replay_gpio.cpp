// Answering the sequencer's GPIO calls from gpio.log (see replay_gpio.hpp).
#include "station/session/replay_gpio.hpp"

#include <fmt/format.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>

#include "station/session/replay_modbus.hpp"

namespace station {
namespace {

namespace dr = station::drivers;

// The role a gpio.log line names ("role=interlock ..."), "" when none.
std::string_view role_of(const SessionLogLine& l) {
  std::string_view d = l.detail;
  const auto at = d.find("role=");
  if (at == std::string_view::npos) return {};
  d.remove_prefix(at + 5);
  return d.substr(0, d.find(' '));
}

std::string describe(const SessionLogLine& l) {
  return fmt::format("line {}: {} {} {}", l.line_no, l.kind, role_of(l),
                     l.bytes.empty() ? -1 : l.bytes[0]);
}

}  // namespace

ReplayGpioBank::ReplayGpioBank(dr::gpio::GpioConfig config, ReplayFeed<SessionLogLine> lines,
                               std::function<std::size_t(double)> syncs_logged_by,
                               std::function<std::size_t()> syncs_sent)
    : config_(std::move(config)),
      lines_(std::move(lines)),
      syncs_logged_by_(std::move(syncs_logged_by)),
      syncs_sent_(std::move(syncs_sent)) {}

const SessionLogLine& ReplayGpioBank::expect(const char* kind, std::string_view role,
                                             const std::string& asked) {
  const SessionLogLine* next = lines_.peek();
  if (next == nullptr) throw ReplayDivergence("gpio", "no more exchanges", asked, 0);
  if (next->kind != kind || role_of(*next) != role || next->bytes.size() != 1)
    throw ReplayDivergence("gpio", describe(*next), asked, next->t_s);
  const SessionLogLine& l = lines_.take();
  signal();
  return l;
}

void ReplayGpioBank::signal() {
  if (!efd_.valid()) return;
  const auto set = [this](bool readable) {  // a syscall only when the fd's state changes
    if (readable == readable_) return;
    std::uint64_t v = 1;
    if (readable)
      (void)!::write(efd_.get(), &v, sizeof v);
    else
      (void)!::read(efd_.get(), &v, sizeof v);  // drain (non-blocking)
    readable_ = readable;
  };
  // The next exchange is an edge drained between ticks when no more SYNCs preceded it than the
  // replay has sent: a tick's own drain comes after that tick's SYNC. (Stamps: SYNCs truncated
  // to the microsecond, session lines rounded, so one instant never orders an edge first.)
  const SessionLogLine* next = lines_.peek();
  set(next != nullptr && next->kind == "gpio-edge" &&
      syncs_logged_by_(next->t_s) <= (syncs_sent_ ? syncs_sent_() : 0));
}

dr::Result<void> ReplayGpioBank::open() {
  efd_.reset(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  readable_ = false;
  open_ = true;
  // Requesting the lines drove every output to its safe level, one write each.
  for (const auto& line : config_.lines) {
    if (line.direction != dr::gpio::GpioDirection::output) continue;
    const auto& l = expect("gpio-write", line.role, "open: safe level of " + line.role);
    if ((l.bytes[0] != 0) != line.safe_level)
      throw ReplayDivergence("gpio", describe(l), "open: safe level of " + line.role, l.t_s);
  }
  signal();
  return {};
}

dr::Result<bool> ReplayGpioBank::read(std::string_view role) {
  return expect("gpio-read", role, fmt::format("read {}", role)).bytes[0] != 0;
}

dr::Result<void> ReplayGpioBank::write(std::string_view role, bool active) {
  const std::string asked = fmt::format("write {} {}", role, active ? 1 : 0);
  const auto& l = expect("gpio-write", role, asked);
  if ((l.bytes[0] != 0) != active) throw ReplayDivergence("gpio", describe(l), asked, l.t_s);
  return {};
}

dr::Result<void> ReplayGpioBank::apply_safe_state() {
  for (const auto& line : config_.lines) {
    if (line.direction == dr::gpio::GpioDirection::output) (void)write(line.role, line.safe_level);
  }
  return {};
}

void ReplayGpioBank::close() {
  // Releasing the lines drove the outputs to their safe levels (the recording's last writes);
  // taken when they are next, never thrown from here (a replay may have stopped early).
  for (const auto& line : config_.lines) {
    const SessionLogLine* l = lines_.peek();
    if (line.direction != dr::gpio::GpioDirection::output || l == nullptr) continue;
    if (l->kind == "gpio-write" && role_of(*l) == line.role) (void)lines_.take();
  }
  open_ = false;
  efd_.reset();
}

dr::Result<std::vector<dr::gpio::GpioEdge>> ReplayGpioBank::read_events() {
  std::vector<dr::gpio::GpioEdge> out;
  while (lines_.peek() != nullptr && lines_.peek()->kind == "gpio-edge") {
    const SessionLogLine& l = lines_.take();
    const auto* cfg = dr::gpio::find_role(config_, role_of(l));
    if (cfg == nullptr || l.bytes.size() != 1)
      throw ReplayDivergence("gpio", describe(l), "an edge of a configured line", l.t_s);
    out.push_back({cfg->role, cfg->where(), l.bytes[0] != 0, l.t_s});
  }
  signal();
  return out;
}

}  // namespace station
