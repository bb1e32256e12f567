// Simulated GPIO chips and bank: pin levels, kernel-like request errors, edges on an eventfd.
#include "sim_devices/gpio_sim.hpp"

#include <fmt/format.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <ctime>
#include <stdexcept>

namespace station::sim {

using drivers::ErrorKind;
using drivers::make_error;
using drivers::Result;
using drivers::gpio::GpioDirection;
using drivers::gpio::GpioEdge;
using drivers::gpio::GpioLineConfig;

namespace {

double monotonic_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

GpioSimChips::GpioSimChips(std::vector<GpioSimChipSpec> chips) {
  for (auto& spec : chips) {
    Chip c{std::move(spec.name), {}};
    for (auto& n : spec.line_names) {
      Pin pin;
      pin.name = std::move(n);
      c.pins.push_back(std::move(pin));
    }
    chips_.push_back(std::move(c));
  }
}

const GpioSimChips::Pin* GpioSimChips::lookup(std::string_view line) const {
  GpioLineConfig where;
  try {
    drivers::gpio::parse_line_spec(line, "", where);
  } catch (const std::invalid_argument&) {
    return nullptr;
  }
  for (const auto& c : chips_) {
    if (!where.chip.empty() && c.name != where.chip) continue;
    if (where.offset >= 0)
      return static_cast<std::size_t>(where.offset) < c.pins.size() ? &c.pins[where.offset]
                                                                    : nullptr;
    for (const auto& p : c.pins)
      if (p.name == where.line_name) return &p;
  }
  return nullptr;
}

GpioSimChips::Pin* GpioSimChips::lookup(std::string_view line) {
  return const_cast<Pin*>(static_cast<const GpioSimChips*>(this)->lookup(line));
}

void GpioSimChips::set_input(std::string_view line, bool level_high) {
  std::lock_guard lock(mu_);
  Pin* p = lookup(line);
  if (p == nullptr)
    throw std::invalid_argument(fmt::format("gpio sim: no line '{}' on any chip", line));
  if (p->output)
    throw std::invalid_argument(fmt::format("gpio sim: line '{}' is a requested output", line));
  if (p->high == level_high) return;
  p->high = level_high;
  if (p->sink) p->sink(level_high, monotonic_s());
}

std::optional<bool> GpioSimChips::pin_level(std::string_view line) const {
  std::lock_guard lock(mu_);
  const Pin* p = lookup(line);
  if (p == nullptr) return std::nullopt;
  return p->high;
}

std::optional<std::string> GpioSimChips::consumer(std::string_view line) const {
  std::lock_guard lock(mu_);
  const Pin* p = lookup(line);
  if (p == nullptr) return std::nullopt;
  return p->consumer;
}

bool GpioSimChips::claimed_as_output(std::string_view line) const {
  std::lock_guard lock(mu_);
  const Pin* p = lookup(line);
  return p != nullptr && p->ever_output;
}

Result<GpioPinId> GpioSimChips::request(const GpioLineConfig& cfg, const std::string& consumer,
                                        bool initial_high, EdgeSink sink) {
  std::lock_guard lock(mu_);
  const std::string what = fmt::format("line {} on {} (role {})", cfg.where(), cfg.chip, cfg.role);
  std::size_t ci = 0;
  while (ci < chips_.size() && chips_[ci].name != cfg.chip) ++ci;
  // Same kinds and wording as LibgpiodBank gives for the kernel's errnos.
  if (ci == chips_.size())
    return make_error(ErrorKind::disconnected,
                      fmt::format("cannot open chip /dev/{} (role {}): No such file or directory",
                                  cfg.chip, cfg.role));
  Chip& chip = chips_[ci];
  unsigned off = 0;
  if (cfg.line_name.empty()) {
    if (cfg.offset < 0 || static_cast<std::size_t>(cfg.offset) >= chip.pins.size())
      return make_error(ErrorKind::range,
                        fmt::format("{}: offset outside 0..{}", what, chip.pins.size() - 1));
    off = static_cast<unsigned>(cfg.offset);
  } else {
    while (off < chip.pins.size() && chip.pins[off].name != cfg.line_name) ++off;
    if (off == chip.pins.size())
      return make_error(ErrorKind::range, what + ": no line with that name on the chip");
  }
  Pin& p = chip.pins[off];
  if (!p.consumer.empty())
    return make_error(
        ErrorKind::io,
        fmt::format("{}: request: Device or resource busy (held by '{}')", what, p.consumer));
  p.consumer = consumer.empty() ? "?" : consumer;
  p.output = cfg.direction == GpioDirection::output;
  p.ever_output = p.ever_output || p.output;
  if (p.output) p.high = initial_high;
  p.sink = std::move(sink);
  return GpioPinId{ci, off};
}

void GpioSimChips::drive(GpioPinId pin, bool level_high) {
  std::lock_guard lock(mu_);
  chips_.at(pin.chip).pins.at(pin.offset).high = level_high;
}

bool GpioSimChips::level(GpioPinId pin) const {
  std::lock_guard lock(mu_);
  return chips_.at(pin.chip).pins.at(pin.offset).high;
}

void GpioSimChips::release(GpioPinId pin) {
  std::lock_guard lock(mu_);
  Pin& p = chips_.at(pin.chip).pins.at(pin.offset);
  p.consumer.clear();
  p.output = false;
  p.sink = nullptr;
}

GpioSimBank::GpioSimBank(drivers::gpio::GpioConfig config, std::shared_ptr<GpioSimChips> chips,
                         std::string device)
    : config_(std::move(config)), chips_(std::move(chips)), device_(std::move(device)) {}

GpioSimBank::~GpioSimBank() {
  close();
}

Result<void> GpioSimBank::open() {
  close();
  efd_.reset(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  if (!efd_.valid())
    return make_error(ErrorKind::io, fmt::format("{}: eventfd: errno {}", device_, errno));
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

Result<void> GpioSimBank::request(const GpioLineConfig& cfg) {
  const bool out = cfg.direction == GpioDirection::output;
  GpioSimChips::EdgeSink sink;
  if (!out)
    sink = [this, &cfg](bool level_high, double mono_s) { on_edge(cfg, level_high, mono_s); };
  auto pin = chips_->request(cfg, config_.consumer, cfg.safe_level != cfg.active_low, sink);
  if (!pin) return make_error(pin.error().kind, device_ + ": " + pin.error().message);
  slots_.push_back(Slot{&cfg, pin.value()});
  if (out && tap_ != nullptr)
    tap_->on_exchange(drivers::gpio::gpio_write_record(device_, cfg, cfg.safe_level));
  return {};
}

void GpioSimBank::on_edge(const GpioLineConfig& cfg, bool level_high, double mono_s) {
  std::lock_guard lock(mu_);
  pending_.push_back(GpioEdge{cfg.role, cfg.where(), level_high != cfg.active_low, mono_s});
  const std::uint64_t one = 1;
  // Non-blocking eventfd: can only fail at counter overflow, when it is readable anyway.
  (void)!::write(efd_.get(), &one, sizeof one);
}

Result<const GpioSimBank::Slot*> GpioSimBank::find_slot(std::string_view role) const {
  if (slots_.empty()) return make_error(ErrorKind::disconnected, device_ + ": not open");
  for (const auto& s : slots_)
    if (s.cfg->role == role) return &s;
  return make_error(ErrorKind::range, fmt::format("{}: no line with role '{}'", device_, role));
}

Result<bool> GpioSimBank::read(std::string_view role) {
  auto s = find_slot(role);
  if (!s) return s.error();
  const bool active = chips_->level(s.value()->pin) != s.value()->cfg->active_low;
  if (tap_ != nullptr)
    tap_->on_exchange(drivers::gpio::gpio_read_record(device_, *s.value()->cfg, active));
  return active;
}

void GpioSimBank::drive(const Slot& slot, bool active) {
  chips_->drive(slot.pin, active != slot.cfg->active_low);
  if (tap_ != nullptr)
    tap_->on_exchange(drivers::gpio::gpio_write_record(device_, *slot.cfg, active));
}

Result<void> GpioSimBank::write(std::string_view role, bool active) {
  auto s = find_slot(role);
  if (!s) return s.error();
  if (s.value()->cfg->direction != GpioDirection::output)
    return make_error(ErrorKind::range,
                      fmt::format("{}: role '{}' is an input, cannot write", device_, role));
  drive(*s.value(), active);
  return {};
}

Result<void> GpioSimBank::apply_safe_state() {
  for (const auto& s : slots_)
    if (s.cfg->direction == GpioDirection::output) drive(s, s.cfg->safe_level);
  return {};
}

void GpioSimBank::close() {
  (void)apply_safe_state();
  for (const auto& s : slots_) chips_->release(s.pin);
  slots_.clear();
  std::lock_guard lock(mu_);
  pending_.clear();
  efd_.reset();
}

Result<std::vector<GpioEdge>> GpioSimBank::read_events() {
  std::lock_guard lock(mu_);
  if (!efd_.valid()) return make_error(ErrorKind::disconnected, device_ + ": not open");
  std::uint64_t count = 0;
  (void)!::read(efd_.get(), &count, sizeof count);  // EAGAIN when nothing pending: fine
  std::vector<GpioEdge> edges(pending_.begin(), pending_.end());
  pending_.clear();
  if (tap_ != nullptr)
    for (const auto& e : edges) tap_->on_exchange(drivers::gpio::gpio_edge_record(device_, e));
  return edges;
}

}  // namespace station::sim
