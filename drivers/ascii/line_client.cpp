// LineClient: exchanges, error translation, reconnect and tap records.
#include "drivers/ascii/line_client.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <variant>

#include "drivers/common/exchange_deadline.hpp"

namespace station::drivers::ascii {

Error translate_line_error(int err, const std::string& what) {
  std::string msg = what + ": " +
                    (err == EMSGSIZE  ? "reply line too long"
                     : err == EBADMSG ? "reply cut short at the deadline"
                                      : std::strerror(err));
  switch (err) {
    case ETIMEDOUT:
    case EAGAIN:
      return make_error(ErrorKind::timeout, msg);
    case EMSGSIZE:
    case EBADMSG:
      return make_error(ErrorKind::protocol, msg);
    case ECONNRESET:
    case ECONNREFUSED:
    case ECONNABORTED:
    case EPIPE:
    case ENOTCONN:
    case EBADF:
    case ENOENT:
    case EHOSTUNREACH:
    case ENETUNREACH:
    case EIO:  // a serial adapter that vanished, a pty whose master closed
    case ENXIO:
    case ENODEV:
    case ESHUTDOWN:  // the peer closed the link (end of stream)
      return make_error(ErrorKind::disconnected, msg);
    default:
      return make_error(ErrorKind::io, msg);
  }
}

LineClient::LineClient(std::string device, LineEndpoint endpoint, LineFraming framing,
                       std::unique_ptr<LineWire> wire, double timeout_s)
    : device_(std::move(device)),
      endpoint_(std::move(endpoint)),
      framing_(std::move(framing)),
      timeout_s_(timeout_s),
      wire_(wire ? std::move(wire) : std::make_unique<FdLineWire>(endpoint_)) {}

Result<void> LineClient::connect() {
  disconnect();
  // While the tick's budget bounds every exchange (exchange_deadline), the connect waits at most
  // what is left of it; none is attempted once it is spent.
  const double connect_s = seconds_left(ExchangeDeadline::bound_s(deadline_after(timeout_s_)));
  if (connect_s <= 0) errno = ETIMEDOUT;
  if (connect_s <= 0 || wire_->open(connect_s) == -1) {
    const int err = errno;
    auto e = translate_line_error(err, device_ + " connect " + to_string(endpoint_));
    if (e.kind != ErrorKind::timeout) e.kind = ErrorKind::disconnected;
    const auto eb = errno_bytes(err);
    tap(TapDirection::event, "ascii-error",
        std::string_view(reinterpret_cast<const char*>(eb.data()), 4), e.message);
    state_.connect_failed(e.message);
    return e;
  }
  state_.connect_succeeded();
  link_.answered();
  tap(TapDirection::event, "ascii-connect", {}, to_string(endpoint_));
  return {};
}

void LineClient::disconnect() {
  if (state_.connected()) tap(TapDirection::event, "ascii-disconnect", {}, to_string(endpoint_));
  wire_->close();
  state_.closed();
}

double LineClient::deadline_after(double timeout_s) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
             .count() +
         timeout_s;
}

double LineClient::seconds_left(double deadline_s) {
  return std::max(0.0, deadline_s - deadline_after(0));
}

Result<void> LineClient::ensure_connected() {
  return state_.ensure(device_, [this] { return connect(); });
}

Error LineClient::fail(int err, const std::string& what) {
  Error e = translate_line_error(err, device_ + " " + what);
  const bool reopen = link_.must_reopen(e.kind, std::holds_alternative<LineTcp>(endpoint_));
  if (reopen && link_.stale_timeouts() > 0)
    e.message += fmt::format(" ({} timeouts in a row: reconnecting)", link_.stale_timeouts());
  const auto eb = errno_bytes(err);
  tap(TapDirection::event, "ascii-error",
      std::string_view(reinterpret_cast<const char*>(eb.data()), 4), e.message);
  if (reopen) {
    disconnect();
  } else if (state_.connected()) {
    wire_->flush();  // a late reply must not be read as the next command's
  }
  return e;
}

Result<void> LineClient::transmit(std::string_view command, double timeout_s) {
  if (auto c = ensure_connected(); !c) return c.error();
  wire_->flush();
  std::string bytes(command);
  bytes += framing_.command_terminator;
  tap(TapDirection::tx, "ascii", bytes, {});  // as sent, terminator included
  if (wire_->send(bytes, timeout_s) == -1) {
    const int err = errno;  // before anything allocates
    return fail(err, fmt::format("send '{}'", command));
  }
  return {};
}

Result<std::string> LineClient::query(std::string_view command) {
  // Its own timeout, or less while the tick's budget bounds every exchange (exchange_deadline).
  const double deadline_s = ExchangeDeadline::bound_s(deadline_after(timeout_s_));
  if (auto t = transmit(command, seconds_left(deadline_s)); !t) return t.error();
  std::string line;
  if (wire_->receive(line, framing_.reply_terminator, seconds_left(deadline_s),
                     framing_.max_reply_bytes) == -1) {
    const int err = errno;
    return fail(err, fmt::format("reply to '{}'", command));
  }
  link_.answered();
  tap(TapDirection::rx, "ascii", line, {});
  return line;
}

Result<void> LineClient::send(std::string_view command) {
  const double deadline_s = ExchangeDeadline::bound_s(deadline_after(timeout_s_));
  if (auto t = transmit(command, seconds_left(deadline_s)); !t) return t;
  link_.answered();
  return {};
}

void LineClient::tap(TapDirection dir, const char* kind, std::string_view bytes,
                     std::string detail) {
  if (tap_ == nullptr) return;
  tap_->on_exchange(TapRecord{tap_wall_time_s(), device_, dir, kind,
                              std::vector<std::uint8_t>(bytes.begin(), bytes.end()),
                              std::move(detail)});
}

}  // namespace station::drivers::ascii
