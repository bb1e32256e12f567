// Reopening a lost CAN link with back-off; an inherited fd is kept and read again instead.
#include "drivers/can/reconnecting_transport.hpp"

#include <fmt/format.h>

namespace station::drivers::can {

namespace {

std::string spec_text(const CanSpec& spec) {
  switch (spec.kind) {
    case CanSpecKind::socketcan:
      return "socketcan:" + spec.target;
    case CanSpecKind::unix_seqpacket:
      return "unix:" + spec.target;
    case CanSpecKind::inherited_fd:
      return "fd:" + spec.target;
  }
  return spec.target;
}

}  // namespace

ReconnectingCanTransport::ReconnectingCanTransport(CanSpec spec, CanOpenOptions options)
    : spec_(std::move(spec)), options_(std::move(options)), name_(spec_text(spec_)) {
  state_.set_clock(options_.clock);
}

Result<void> ReconnectingCanTransport::open() {
  if (link_) return {};
  auto t = open_can_transport(spec_, options_);
  if (!t) {
    state_.connect_failed(t.error().message);
    tap_event("error", state_.last_error());
    return make_error(ErrorKind::disconnected, state_.last_error());
  }
  link_ = std::move(t).value();
  state_.connect_succeeded();
  tap_event("connect", name_);
  return {};
}

Result<void> ReconnectingCanTransport::ensure_open() {
  return state_.ensure(name_, [this] { return open(); });
}

Error ReconnectingCanTransport::lost(Error e) {
  if (e.kind != ErrorKind::disconnected) return e;
  if (spec_.kind == CanSpecKind::inherited_fd) {
    // Nothing names the peer again: keep the descriptor and keep reading it.
    e.message += "; an inherited fd cannot be reopened, it is read again on every tick";
    return e;
  }
  state_.lost(e.message);
  link_.reset();
  tap_event("disconnect", e.message);
  e.message += "; reconnecting";
  return e;
}

Result<void> ReconnectingCanTransport::send(const can_frame& frame) {
  if (auto o = ensure_open(); !o) return o;
  if (auto r = link_->send(frame); !r) return lost(r.error());
  return {};
}

Result<can_frame> ReconnectingCanTransport::receive(std::chrono::milliseconds timeout) {
  if (auto o = ensure_open(); !o) return o.error();
  auto f = link_->receive(timeout);
  if (!f) return lost(f.error());
  last_rx_time_s_ = link_->last_rx_time_s();
  return f;
}

int ReconnectingCanTransport::fd() const {
  return link_ ? link_->fd() : -1;
}

void ReconnectingCanTransport::tap_event(const char* kind, const std::string& detail) const {
  if (options_.tap == nullptr) return;
  TapRecord r;
  r.wall_time_s = tap_wall_time_s();
  r.device = options_.tap_device;
  r.direction = TapDirection::event;
  r.kind = kind;
  r.detail = detail;
  options_.tap->on_exchange(r);
}

}  // namespace station::drivers::can
