// LibmodbusWire: libmodbus opens the link; every exchange is a poll() on its descriptor against
// one deadline for the whole transaction (modbus_frame.hpp: why, and what libmodbus does).
#include "drivers/modbus/modbus_wire.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <thread>
#include <variant>

#include "drivers/common/exchange_deadline.hpp"
#include "drivers/modbus/modbus_adu.hpp"

namespace station::drivers::modbus {
namespace {

using Steady = std::chrono::steady_clock;

// Replies abandoned before their first byte whose ids are still remembered (TCP): a server
// answers in order, so a handful covers every late reply still on its way.
constexpr std::size_t kLateIdsKept = 8;

// Waits for `events` on fd until `deadline`: 1 ready, -1 with errno (ETIMEDOUT at the deadline).
// Bytes already there are taken even at or past the deadline (a flush that must not wait).
int wait_for(int fd, short events, Steady::time_point deadline) {
  for (;;) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Steady::now());
    pollfd p{fd, events, 0};
    const int rc = ::poll(&p, 1, static_cast<int>(std::max<std::int64_t>(0, left.count())));
    if (rc < 0 && errno == EINTR) continue;
    if (rc < 0) return -1;
    if (rc == 0 && Steady::now() >= deadline) {
      errno = ETIMEDOUT;
      return -1;
    }
    if (rc == 0) continue;
    if ((p.revents & (POLLERR | POLLNVAL)) != 0 && (p.revents & events) == 0) {
      errno = EIO;
      return -1;
    }
    return 1;
  }
}

// Reads at most `n` bytes onto `out` by the deadline; -1 with errno (ECONNRESET: the peer
// closed). A serial line is a descriptor, not a socket: read() serves both. `try_first` (TCP): the
// rest of a frame begun, which has usually come in the segment of its start, is read without
// waiting (MSG_DONTWAIT) and polled for only when it is not there: one poll fewer per reply.
int read_some(int fd, std::vector<std::uint8_t>& out, std::size_t n, Steady::time_point deadline,
              bool try_first) {
  std::uint8_t buf[256];
  for (;;) {
    ssize_t got = -1;
    if (try_first) {
      got = ::recv(fd, buf, std::min(n, sizeof buf), MSG_DONTWAIT);
      if (got < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR && errno != ENOTSOCK)
        return -1;
      try_first = false;
    }
    if (got < 0) {
      if (wait_for(fd, POLLIN, deadline) == -1) return -1;
      got = ::read(fd, buf, std::min(n, sizeof buf));
    }
    if (got == 0) {
      errno = ECONNRESET;
      return -1;
    }
    if (got < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (got < 0) return -1;
    out.insert(out.end(), buf, buf + got);
    return 0;
  }
}

// Bytes still to read of the frame begun in `frame` (0: it is whole), or -1: it frames nothing.
int still_needed(Framing f, const std::vector<std::uint8_t>& frame) {
  const int whole = reply_frame_length(f, frame);
  if (whole < 0) return -1;
  if (whole > 0) return std::max(0, whole - static_cast<int>(frame.size()));
  return f == Framing::tcp ? 6 - static_cast<int>(frame.size()) : 1;  // until its length shows
}

// Sets libmodbus's timeouts, which bound only its connect here, to `s` seconds (it refuses 0 s and
// more than 999999 µs: split whole microseconds, at least one).
void set_connect_timeout(modbus_t* ctx, double s) {
  const long long us = std::max(1LL, std::llround(s * 1e6));
  const auto sec = static_cast<std::uint32_t>(us / 1000000);
  const auto usec = static_cast<std::uint32_t>(us % 1000000);
  modbus_set_response_timeout(ctx, sec, usec);
  modbus_set_byte_timeout(ctx, sec, usec);
}

}  // namespace

int ModbusWire::read_batch(std::span<const ReadRequest> requests) {
  int done = 0;
  for (const auto& r : requests) {
    const int rc = read(r.fc, r.unit, r.addr, r.count, r.dest);
    if (rc == -1) return done;
    if (rc != r.count) {
      errno = EMBBADDATA;  // as ModbusClient reads a short count
      return done;
    }
    ++done;
  }
  return done;
}

double LibmodbusWire::quiet_interval_s(const RtuEndpoint& ep, double timeout_s) {
  const int bits = 1 + ep.data_bits + (ep.parity == 'N' ? 0 : 1) + ep.stop_bits;
  const double t35_s = ep.baud > 19200 ? 1.75e-3 : 3.5 * bits / ep.baud;
  return std::max(t35_s, timeout_s / 4);
}

int LibmodbusWire::open(double timeout_s) {
  close();
  ctx_ = make_context(endpoint_);
  // libmodbus's response timeout bounds its TCP connect (modbus-tcp.c `_connect`: a select() on
  // the non-blocking socket, per address); while an ExchangeDeadline is on, what is left of it.
  const auto now = SteadyClock::now();
  const double connect_s = std::min(
      timeout_s,
      std::chrono::duration<double>(ExchangeDeadline::bound(now + to_steady(timeout_s)) - now)
          .count());
  if (connect_s <= 0) {  // the budget is spent: no connect is attempted
    ctx_.reset();
    errno = ETIMEDOUT;
    return -1;
  }
  set_connect_timeout(ctx_.get(), connect_s);
  if (modbus_connect(ctx_.get()) == -1) {
    const int err = errno;
    ctx_.reset();
    errno = err;
    return -1;
  }
  timeout_ = to_steady(timeout_s);
  if (const auto* rtu = std::get_if<RtuEndpoint>(&endpoint_))
    quiet_ = to_steady(quiet_interval_s(*rtu, timeout_s));
  return 0;
}

void LibmodbusWire::close() {
  ctx_.reset();
  tid_ = 0;
  late_.clear();
  late_ids_.clear();
  rx_.clear();
}

Framing LibmodbusWire::framing() const {
  return std::holds_alternative<TcpEndpoint>(endpoint_) ? Framing::tcp : Framing::rtu;
}

bool LibmodbusWire::rest(SteadyClock::time_point deadline) {
  if (gap_ <= SteadyClock::duration::zero()) return true;
  if (last_end_ + gap_ >= deadline) return false;
  std::this_thread::sleep_until(last_end_ + gap_);
  return true;
}

int LibmodbusWire::wait_quiet(SteadyClock::time_point deadline) {
  if (!in_flight_) return 0;
  const int fd = modbus_get_socket(ctx_.get());
  for (;;) {
    if (quiet_since_ + quiet_ > deadline) {
      errno = ETIMEDOUT;
      return -1;
    }
    if (wait_for(fd, POLLIN, quiet_since_ + quiet_) == -1) {
      if (errno != ETIMEDOUT) return -1;
      in_flight_ = false;  // quiet for the interval: whatever was on its way has come
      return 0;
    }
    std::uint8_t buf[256];
    const ssize_t got = ::read(fd, buf, sizeof buf);
    if (got == 0) errno = ECONNRESET;
    if (got <= 0 && errno != EINTR && errno != EAGAIN) return -1;
    quiet_since_ = SteadyClock::now();
  }
}

int LibmodbusWire::ended(int rc) {
  const int err = errno;
  last_end_ = SteadyClock::now();
  errno = err;
  return rc;
}

int LibmodbusWire::send_frame(const std::vector<std::uint8_t>& frame,
                              SteadyClock::time_point deadline) {
  const int fd = modbus_get_socket(ctx_.get());
  std::size_t done = 0;
  while (done < frame.size()) {
    const std::size_t left = frame.size() - done;
    ssize_t n = ::send(fd, frame.data() + done, left, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0 && errno == ENOTSOCK) n = ::write(fd, frame.data() + done, left);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n == 0) errno = EAGAIN;  // nothing taken: wait for room, by the deadline
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) return -1;
    if (wait_for(fd, POLLOUT, deadline) == -1) return -1;
  }
  return 0;
}

int LibmodbusWire::receive_frame(std::vector<std::uint8_t>& frame,
                                 SteadyClock::time_point deadline) {
  const int fd = modbus_get_socket(ctx_.get());
  for (;;) {
    const int need = still_needed(framing(), frame);
    if (need < 0) {
      errno = EMBBADDATA;  // as libmodbus: "too many data", or no reply has this function
      return -1;
    }
    if (need == 0) return 0;
    if (!rx_.empty()) {  // read ahead by a batch: the stream's next bytes
      const auto take = static_cast<std::ptrdiff_t>(std::min<std::size_t>(need, rx_.size()));
      frame.insert(frame.end(), rx_.begin(), rx_.begin() + take);
      rx_.erase(rx_.begin(), rx_.begin() + take);
      continue;
    }
    const bool rest_of_tcp_frame = !frame.empty() && framing() == Framing::tcp;
    if (read_some(fd, frame, static_cast<std::size_t>(need), deadline, rest_of_tcp_frame) == -1)
      return -1;
  }
}

int LibmodbusWire::receive_batch_frame(std::vector<std::uint8_t>& frame,
                                       SteadyClock::time_point deadline) {
  constexpr std::size_t kReadAhead = 256;  // read_some's most: a batch's replies in one read
  if (rx_.empty() &&
      read_some(modbus_get_socket(ctx_.get()), rx_, kReadAhead, deadline, false) == -1)
    return -1;
  return receive_frame(frame, deadline);
}

void LibmodbusWire::abandon(std::uint16_t tid) {
  if (late_ids_.size() == kLateIdsKept) late_ids_.erase(late_ids_.begin());
  late_ids_.push_back(tid);
}

int LibmodbusWire::drop_late(SteadyClock::time_point deadline) {
  if (late_.empty()) return 0;
  const int rc = receive_frame(late_, deadline);
  if (rc == -1 && errno == ETIMEDOUT) return -1;  // still dripping: this exchange waited for it
  if (rc == -1) modbus_flush(ctx_.get());         // it frames nothing: drop what is there
  late_.clear();
  quiet_since_ = SteadyClock::now();  // RTU: the quiet wait counts from its last byte
  return 0;
}

int LibmodbusWire::begin(SteadyClock::time_point deadline) {
  if (!rest(deadline)) {  // no time to keep the gap: not attempted, the gap still due next time
    errno = ETIMEDOUT;
    return -1;
  }
  if (drop_late(deadline) == -1) {
    errno = ETIME;  // the last reply still drips: this one cannot begin
    return ended(-1);
  }
  if (framing() == Framing::rtu && wait_quiet(deadline) == -1) return -1;  // nothing was sent
  // On a serial line a late reply has no id to tell it by: what came between exchanges goes.
  if (framing() == Framing::rtu) modbus_flush(ctx_.get());
  if (SteadyClock::now() >= deadline) {  // the tick's budget is spent: nothing is sent
    errno = ETIMEDOUT;
    return ended(-1);
  }
  return 0;
}

int LibmodbusWire::exchange(const std::vector<std::uint8_t>& adu,
                            std::vector<std::uint8_t>& reply) {
  if (!ctx_) {
    errno = ENOTCONN;
    return -1;
  }
  // Its own timeout from the request gap's end, or less while the tick's budget bounds every
  // exchange (exchange_deadline): the gap, a late reply's rest and the quiet wait count in it.
  const auto start = std::max(SteadyClock::now(), last_end_ + gap_);
  const auto deadline = ExchangeDeadline::bound(start + timeout_);
  if (begin(deadline) == -1) return -1;
  tid_ = static_cast<std::uint16_t>(tid_ + 1);
  const auto request = request_frame(framing(), tid_, adu);
  if (send_frame(request, deadline) == -1) return ended(-1);
  for (;;) {
    reply.clear();
    if (receive_frame(reply, deadline) == -1) {
      // RTU: its reply (or the rest of it) may still come; the next request waits for quiet.
      if (errno == ETIMEDOUT && framing() == Framing::rtu) {
        in_flight_ = true;
        quiet_since_ = SteadyClock::now();
      }
      if (errno == ETIMEDOUT && reply.empty() && framing() == Framing::tcp) abandon(tid_);
      if (errno == ETIMEDOUT && !reply.empty()) {
        late_ = reply;  // its rest is dropped as it comes
        errno = ETIME;  // begun, not finished by the deadline
      }
      return ended(-1);
    }
    // TCP: a whole late reply to an exchange abandoned before its first byte is dropped by its
    // transaction id, which exists for this (Implementation Guide §3.1.3); libmodbus would fail.
    const auto late = std::find(late_ids_.begin(), late_ids_.end(), transaction_id(reply));
    if (framing() == Framing::tcp && transaction_id(reply) != tid_ && late != late_ids_.end()) {
      late_ids_.erase(late);
      continue;
    }
    late_ids_.clear();  // a server answers in order: nothing older is still coming
    if (const int err = check_reply(framing(), request, reply); err != 0) {
      errno = err;
      return ended(-1);
    }
    return ended(0);
  }
}

int LibmodbusWire::read(FunctionCode fc, int unit, std::uint16_t addr, int count,
                        std::uint16_t* dest) {
  std::vector<std::uint8_t> reply;
  if (exchange(read_request_adu(unit, static_cast<int>(fc), addr, count), reply) == -1) return -1;
  reply_words(framing(), reply, count, dest);
  return count;
}

int LibmodbusWire::write(int unit, std::uint16_t addr, std::span<const std::uint16_t> words) {
  std::vector<std::uint8_t> reply;
  if (exchange(write_request_adu(unit, addr, words), reply) == -1) return -1;
  return static_cast<int>(words.size());
}

void LibmodbusWire::flush() {
  if (!ctx_) return;
  // What has come of an abandoned reply is framed and dropped now (no wait); its rest later.
  if (!late_.empty() && drop_late(SteadyClock::now()) == -1) return;
  rx_.clear();
  modbus_flush(ctx_.get());
}

}  // namespace station::drivers::modbus
