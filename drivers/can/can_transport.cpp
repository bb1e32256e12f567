// CAN transports: one fd-based implementation (poll + recvmsg) behind SocketCAN, unix, fd specs.
#include "drivers/can/can_transport.hpp"

#include <fmt/format.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

namespace station::drivers::can {
namespace {

// Translates an errno from `op` on transport `name` into a typed Error (the one place we do so).
Error errno_error(const std::string& name, const char* op, int err) {
  // EAGAIN on a non-blocking call means "nothing now": the caller's wait decides about time.
  // A vanished interface (USB adapter unplugged, link set down) is a lost link too.
  const bool lost = err == EPIPE || err == ECONNRESET || err == ENOTCONN || err == EBADF ||
                    err == ENETDOWN || err == ENODEV || err == ENXIO;
  const ErrorKind kind = lost                                    ? ErrorKind::disconnected
                         : (err == EAGAIN || err == EWOULDBLOCK) ? ErrorKind::timeout
                                                                 : ErrorKind::io;
  return make_error(kind, fmt::format("{}: {} failed: {} ({})", name, op, std::strerror(err),
                                      strerrorname_np(err) ? strerrorname_np(err) : "?"));
}

std::vector<std::uint8_t> frame_bytes(const can_frame& f) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&f);
  return {p, p + sizeof f};
}

class FdCanTransport final : public CanTransport {
 public:
  FdCanTransport(UniqueFd fd, CanOpenOptions options, std::string name)
      : fd_(std::move(fd)), options_(std::move(options)), name_(std::move(name)) {}

  Result<void> send(const can_frame& frame) override;
  Result<can_frame> receive(std::chrono::milliseconds timeout) override;
  int fd() const override { return fd_.get(); }
  double last_rx_time_s() const override { return last_rx_time_s_; }

 private:
  Result<void> wait(short events, std::chrono::milliseconds timeout, const char* what);
  Result<can_frame> read_one();
  Result<void> fill();
  Result<can_frame> take(const mmsghdr& m);
  void tap(TapDirection dir, const can_frame& f, double t, std::string detail = {}) const;

  // Received records are read in batches (one recvmmsg for a burst of board answers) and handed
  // out one by one; each keeps its own length, flags and kernel timestamp.
  static constexpr std::size_t kBatch = 32;
  struct RxSlot {
    alignas(can_frame) std::uint8_t buf[2 * sizeof(can_frame) + 64];
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval))];
    iovec iov;
  };

  UniqueFd fd_;
  CanOpenOptions options_;
  std::string name_;
  double last_rx_time_s_ = 0;
  std::array<RxSlot, kBatch> rx_{};
  std::array<mmsghdr, kBatch> rx_msgs_{};
  std::size_t rx_next_ = 0, rx_count_ = 0;
};

Result<void> FdCanTransport::wait(short events, std::chrono::milliseconds timeout,
                                  const char* what) {
  pollfd p{fd_.get(), events, 0};
  const int ms = timeout.count() < 0 ? 0 : static_cast<int>(timeout.count());
  for (;;) {
    const int r = ::poll(&p, 1, ms);
    if (r < 0 && errno == EINTR) continue;  // a signal is no reason to give up the wait early
    if (r < 0) return errno_error(name_, "poll", errno);
    if (r == 0)
      return make_error(ErrorKind::timeout, fmt::format("{}: no {} within {} ms", name_, what, ms));
    if ((p.revents & events) == 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL)))
      return make_error(ErrorKind::disconnected, fmt::format("{}: peer closed", name_));
    return {};
  }
}

Result<void> FdCanTransport::send(const can_frame& frame) {
  if (!fd_.valid()) return make_error(ErrorKind::disconnected, name_ + ": not open");
  ssize_t n = ::send(fd_.get(), &frame, sizeof frame, MSG_NOSIGNAL | MSG_DONTWAIT);
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {  // buffer full: wait, bounded
    if (auto w = wait(POLLOUT, options_.send_timeout, "send buffer space"); !w) return w;
    n = ::send(fd_.get(), &frame, sizeof frame, MSG_NOSIGNAL | MSG_DONTWAIT);
  }
  if (n < 0) return errno_error(name_, "send", errno);
  if (static_cast<std::size_t>(n) != sizeof frame)
    return make_error(ErrorKind::io, fmt::format("{}: short send of {} bytes", name_, n));
  tap(TapDirection::tx, frame, tap_wall_time_s());
  return {};
}

Result<can_frame> FdCanTransport::receive(std::chrono::milliseconds timeout) {
  if (!fd_.valid()) return make_error(ErrorKind::disconnected, name_ + ": not open");
  // Frames usually queue up faster than they are read: try first, poll only when none is there.
  auto f = read_one();
  if (f || f.error().kind != ErrorKind::timeout) return f;
  if (auto w = wait(POLLIN, timeout, "frame"); !w) return w.error();
  return read_one();
}

Result<void> FdCanTransport::fill() {
  for (std::size_t i = 0; i < kBatch; ++i) {
    rx_[i].iov = {rx_[i].buf, sizeof rx_[i].buf};
    rx_msgs_[i] = {};
    rx_msgs_[i].msg_hdr.msg_iov = &rx_[i].iov;
    rx_msgs_[i].msg_hdr.msg_iovlen = 1;
    rx_msgs_[i].msg_hdr.msg_control = rx_[i].control;
    rx_msgs_[i].msg_hdr.msg_controllen = sizeof rx_[i].control;
  }
  const int n = ::recvmmsg(fd_.get(), rx_msgs_.data(), kBatch, MSG_DONTWAIT, nullptr);
  if (n < 0) return errno_error(name_, "recvmmsg", errno);
  rx_next_ = 0;
  rx_count_ = static_cast<std::size_t>(n);
  if (n == 0) return make_error(ErrorKind::disconnected, name_ + ": peer closed");
  return {};
}

Result<can_frame> FdCanTransport::read_one() {
  if (rx_next_ >= rx_count_) {
    if (auto r = fill(); !r) return r.error();
  }
  return take(rx_msgs_[rx_next_++]);
}

Result<can_frame> FdCanTransport::take(const mmsghdr& m) {
  const auto n = static_cast<ssize_t>(m.msg_len);
  const msghdr& msg = m.msg_hdr;
  if (n == 0) return make_error(ErrorKind::disconnected, name_ + ": peer closed");
  last_rx_time_s_ = tap_wall_time_s();
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(const_cast<msghdr*>(&msg), c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMP) {
      timeval tv;
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      last_rx_time_s_ = static_cast<double>(tv.tv_sec) + 1e-6 * static_cast<double>(tv.tv_usec);
    }
  }
  if (static_cast<std::size_t>(n) != sizeof(can_frame) || (msg.msg_flags & MSG_TRUNC)) {
    can_frame none{};
    tap(TapDirection::rx, none, last_rx_time_s_, fmt::format("bad record of {} bytes", n));
    return make_error(
        ErrorKind::protocol,
        fmt::format("{}: read {} bytes, a can_frame record is {}", name_, n, sizeof(can_frame)));
  }
  can_frame f;
  std::memcpy(&f, msg.msg_iov->iov_base, sizeof f);
  tap(TapDirection::rx, f, last_rx_time_s_);
  return f;
}

void FdCanTransport::tap(TapDirection dir, const can_frame& f, double t, std::string detail) const {
  if (!options_.tap) return;
  TapRecord r;
  r.wall_time_s = t;
  r.device = options_.tap_device;
  r.direction = dir;
  r.kind = detail.empty() ? "can" : "error";
  if (detail.empty()) r.bytes = frame_bytes(f);
  r.detail = std::move(detail);
  options_.tap->on_exchange(r);
}

Result<UniqueFd> open_socketcan(const CanSpec& spec, const CanOpenOptions& o, std::string& name) {
  name = "socketcan:" + spec.target;
  UniqueFd fd(::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW));
  if (!fd.valid()) return errno_error(name, "socket(PF_CAN, SOCK_RAW, CAN_RAW)", errno);
  if (!o.filters.empty() &&
      ::setsockopt(fd.get(), SOL_CAN_RAW, CAN_RAW_FILTER, o.filters.data(),
                   static_cast<socklen_t>(o.filters.size() * sizeof(can_filter))) < 0)
    return errno_error(name, "setsockopt(CAN_RAW_FILTER)", errno);
  const int on = 1;
  if (::setsockopt(fd.get(), SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on) < 0)
    return errno_error(name, "setsockopt(SO_TIMESTAMP)", errno);
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(::if_nametoindex(spec.target.c_str()));
  if (addr.can_ifindex == 0) return errno_error(name, "if_nametoindex", errno);
  if (::bind(fd.get(), reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0)
    return errno_error(name, "bind", errno);
  return fd;
}

Result<UniqueFd> open_unix(const CanSpec& spec, std::string& name) {
  name = "unix:" + spec.target;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (spec.target.size() >= sizeof addr.sun_path)
    return make_error(ErrorKind::range, name + ": socket path too long");
  std::memcpy(addr.sun_path, spec.target.data(), spec.target.size());
  // Non-blocking, so a peer whose accept backlog is full cannot stall a tick in connect().
  UniqueFd fd(::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!fd.valid()) return errno_error(name, "socket(AF_UNIX, SOCK_SEQPACKET)", errno);
  if (::connect(fd.get(), reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0)
    return errno_error(name, "connect", errno);
  const int on = 1;
  ::setsockopt(fd.get(), SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on);  // best effort on AF_UNIX
  return fd;
}

}  // namespace

CanSpec parse_can_spec(std::string_view spec) {
  const auto colon = spec.find(':');
  const std::string_view scheme = spec.substr(0, colon);
  const std::string_view rest = colon == spec.npos ? std::string_view{} : spec.substr(colon + 1);
  auto bad = [&](const char* why) {
    return std::invalid_argument(fmt::format("CAN transport spec '{}': {}", spec, why));
  };
  if (colon == spec.npos || rest.empty()) throw bad("expected socketcan:IFACE, unix:PATH or fd:N");
  CanSpec out;
  out.target = std::string(rest);
  if (scheme == "socketcan") {
    if (rest.size() >= IFNAMSIZ) throw bad("interface name too long");
    out.kind = CanSpecKind::socketcan;
  } else if (scheme == "unix") {
    out.kind = CanSpecKind::unix_seqpacket;
  } else if (scheme == "fd") {
    out.kind = CanSpecKind::inherited_fd;
    const auto [p, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), out.fd);
    if (ec != std::errc{} || p != rest.data() + rest.size() || out.fd < 0)
      throw bad("fd must be a non-negative integer");
  } else {
    throw bad("unknown scheme (socketcan, unix, fd)");
  }
  return out;
}

Result<std::unique_ptr<CanTransport>> open_can_transport(const CanSpec& spec,
                                                         const CanOpenOptions& options) {
  std::string name = "fd:" + spec.target;
  Result<UniqueFd> fd = UniqueFd();
  if (spec.kind == CanSpecKind::inherited_fd) fd = UniqueFd(spec.fd);
  if (spec.kind == CanSpecKind::socketcan) fd = open_socketcan(spec, options, name);
  if (spec.kind == CanSpecKind::unix_seqpacket) fd = open_unix(spec, name);
  if (!fd) return fd.error();
  return make_fd_transport(std::move(fd).value(), options, std::move(name));
}

std::unique_ptr<CanTransport> make_fd_transport(UniqueFd fd, const CanOpenOptions& options,
                                                std::string name) {
  return std::make_unique<FdCanTransport>(std::move(fd), options, std::move(name));
}

}  // namespace station::drivers::can
