// libgpiod v1 bank: chip/line lookup, requests with safe defaults, one epoll fd over the per-line
// event fds, errno -> ErrorKind translation.
#include "drivers/gpio/libgpiod_bank.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/epoll.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

namespace station::drivers::gpio {

namespace {

constexpr unsigned kEventBatch = 16;

// The one place libgpiod/errno failures become typed errors.
Error errno_error(int err, const std::string& what) {
  ErrorKind kind = ErrorKind::io;
  if (err == ENOENT || err == ENODEV || err == ENXIO) kind = ErrorKind::disconnected;
  if (err == EINVAL) kind = ErrorKind::range;
  return make_error(kind, fmt::format("{}: {}", what, std::strerror(err)));
}

double to_seconds(const timespec& ts) {
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

int request_flags(const GpioLineConfig& cfg) {
  return cfg.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
}

}  // namespace

LibgpiodBank::LibgpiodBank(GpioConfig config, std::string device)
    : config_(std::move(config)), device_(std::move(device)) {}

LibgpiodBank::~LibgpiodBank() {
  close();
}

Result<void> LibgpiodBank::open() {
  close();
  epoll_.reset(::epoll_create1(EPOLL_CLOEXEC));
  if (!epoll_.valid()) return errno_error(errno, device_ + ": epoll_create1");
  slots_.reserve(config_.lines.size());
  for (const auto& cfg : config_.lines) {
    auto r = request(cfg);
    if (!r) {
      close();
      return r;
    }
  }
  return {};
}

Result<gpiod_chip*> LibgpiodBank::chip_for(const GpioLineConfig& cfg) {
  if (auto it = chips_.find(cfg.chip); it != chips_.end()) return it->second.get();
  ChipHandle chip(gpiod_chip_open_by_name(cfg.chip.c_str()));
  if (!chip)
    return errno_error(
        errno, fmt::format("{}: cannot open chip /dev/{} (role {})", device_, cfg.chip, cfg.role));
  gpiod_chip* raw = chip.get();
  chips_.emplace(cfg.chip, std::move(chip));
  return raw;
}

Result<void> LibgpiodBank::request(const GpioLineConfig& cfg) {
  auto chip = chip_for(cfg);
  if (!chip) return chip.error();
  const std::string what =
      fmt::format("{}: line {} on {} (role {})", device_, cfg.where(), cfg.chip, cfg.role);
  gpiod_line* line = nullptr;
  if (!cfg.line_name.empty()) {
    errno = 0;
    line = gpiod_chip_find_line(chip.value(), cfg.line_name.c_str());
    if (line == nullptr && (errno == ENOENT || errno == 0))
      return make_error(ErrorKind::range, what + ": no line with that name on the chip");
  } else if (cfg.offset < 0 ||
             static_cast<unsigned>(cfg.offset) >= gpiod_chip_num_lines(chip.value())) {
    return make_error(ErrorKind::range, fmt::format("{}: offset outside 0..{}", what,
                                                    gpiod_chip_num_lines(chip.value()) - 1));
  } else {
    line = gpiod_chip_get_line(chip.value(), static_cast<unsigned>(cfg.offset));
  }
  if (line == nullptr) return errno_error(errno, what + ": lookup");

  const bool out = cfg.direction == GpioDirection::output;
  const int rc = out ? gpiod_line_request_output_flags(line, config_.consumer.c_str(),
                                                       request_flags(cfg), cfg.safe_level ? 1 : 0)
                     : gpiod_line_request_both_edges_events_flags(line, config_.consumer.c_str(),
                                                                  request_flags(cfg));
  if (rc != 0) return errno_error(errno, what + ": request");
  slots_.push_back(Slot{&cfg, RequestedLine(line, out, cfg.safe_level ? 1 : 0)});
  if (out) {
    tap(gpio_write_record(device_, cfg, cfg.safe_level));
    return {};
  }
  return watch(slots_.size() - 1);
}

Result<void> LibgpiodBank::watch(std::size_t slot_index) {
  const Slot& slot = slots_[slot_index];
  const int fd = gpiod_line_event_get_fd(slot.line.get());
  const std::string what =
      fmt::format("{}: line {} (role {})", device_, slot.cfg->where(), slot.cfg->role);
  if (fd < 0) return errno_error(errno, what + ": event fd");
  // Non-blocking, so a read after a spurious wake-up returns EAGAIN instead of hanging.
  const int fl = ::fcntl(fd, F_GETFL);
  if (fl < 0 || ::fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0)
    return errno_error(errno, what + ": O_NONBLOCK");
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.u64 = slot_index;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd, &ev) != 0)
    return errno_error(errno, what + ": epoll_ctl");
  return {};
}

LibgpiodBank::Slot* LibgpiodBank::find_slot(std::string_view role) {
  for (auto& s : slots_)
    if (s.cfg->role == role) return &s;
  return nullptr;
}

Result<bool> LibgpiodBank::read(std::string_view role) {
  if (slots_.empty()) return make_error(ErrorKind::disconnected, device_ + ": not open");
  Slot* s = find_slot(role);
  if (s == nullptr)
    return make_error(ErrorKind::range, fmt::format("{}: no line with role '{}'", device_, role));
  const int v = gpiod_line_get_value(s->line.get());
  if (v < 0) return errno_error(errno, fmt::format("{}: read {}", device_, role));
  tap(gpio_read_record(device_, *s->cfg, v != 0));
  return v != 0;
}

Result<void> LibgpiodBank::set_value(const Slot& slot, bool active) {
  if (gpiod_line_set_value(slot.line.get(), active ? 1 : 0) != 0)
    return errno_error(errno, fmt::format("{}: write {}", device_, slot.cfg->role));
  tap(gpio_write_record(device_, *slot.cfg, active));
  return {};
}

Result<void> LibgpiodBank::write(std::string_view role, bool active) {
  if (slots_.empty()) return make_error(ErrorKind::disconnected, device_ + ": not open");
  Slot* s = find_slot(role);
  if (s == nullptr)
    return make_error(ErrorKind::range, fmt::format("{}: no line with role '{}'", device_, role));
  if (s->cfg->direction != GpioDirection::output)
    return make_error(ErrorKind::range,
                      fmt::format("{}: role '{}' is an input, cannot write", device_, role));
  return set_value(*s, active);
}

Result<void> LibgpiodBank::apply_safe_state() {
  Result<void> first;
  for (const auto& s : slots_) {
    if (s.cfg->direction != GpioDirection::output) continue;
    auto r = set_value(s, s.cfg->safe_level);
    if (!r && first) first = r;
  }
  return first;
}

void LibgpiodBank::close() {
  if (!slots_.empty()) (void)apply_safe_state();
  slots_.clear();  // each RequestedLine drives safe again and releases
  chips_.clear();
  epoll_.reset();
}

Result<void> LibgpiodBank::drain(const Slot& slot, std::vector<GpioEdge>& out) {
  std::array<gpiod_line_event, kEventBatch> buf{};
  for (;;) {
    const int n = gpiod_line_event_read_multiple(slot.line.get(), buf.data(), kEventBatch);
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return {};
      return errno_error(errno, fmt::format("{}: events of {}", device_, slot.cfg->role));
    }
    for (int i = 0; i < n; ++i)
      out.push_back(GpioEdge{slot.cfg->role, slot.cfg->where(),
                             buf[i].event_type == GPIOD_LINE_EVENT_RISING_EDGE,
                             to_seconds(buf[i].ts)});
    if (static_cast<unsigned>(n) < kEventBatch) return {};
  }
}

Result<std::vector<GpioEdge>> LibgpiodBank::read_events() {
  if (!epoll_.valid()) return make_error(ErrorKind::disconnected, device_ + ": not open");
  std::array<epoll_event, kEventBatch> ready{};
  const int n = ::epoll_wait(epoll_.get(), ready.data(), static_cast<int>(ready.size()), 0);
  if (n < 0) return errno_error(errno, device_ + ": epoll_wait");
  std::vector<GpioEdge> edges;
  for (int i = 0; i < n; ++i) {
    auto r = drain(slots_.at(ready[i].data.u64), edges);
    if (!r) return r.error();
  }
  // Lines are drained one after another; the kernel stamps give the true order.
  std::stable_sort(edges.begin(), edges.end(), [](const GpioEdge& a, const GpioEdge& b) {
    return a.timestamp_s < b.timestamp_s;
  });
  for (const auto& e : edges) tap(gpio_edge_record(device_, e));
  return edges;
}

void LibgpiodBank::tap(const TapRecord& record) noexcept {
  if (tap_ != nullptr) tap_->on_exchange(record);
}

}  // namespace station::drivers::gpio
