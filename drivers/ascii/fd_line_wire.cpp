// FdLineWire: non-blocking descriptors, every wait a poll() with the remaining deadline.
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <memory>

#include "drivers/ascii/line_wire.hpp"

namespace station::drivers::ascii {
namespace {

using Steady = std::chrono::steady_clock;

Steady::time_point deadline_after(double s) {
  return Steady::now() + std::chrono::microseconds(static_cast<long long>(std::max(0.0, s) * 1e6));
}

// Waits for `events` on fd until `deadline`: 1 ready, 0 timed out (errno ETIMEDOUT), -1 error.
int wait_for(int fd, short events, Steady::time_point deadline) {
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Steady::now());
    if (left.count() < 0) {
      errno = ETIMEDOUT;
      return 0;
    }
    pollfd p{fd, events, 0};
    const int rc = ::poll(&p, 1, static_cast<int>(left.count()) + 1);
    if (rc < 0 && errno == EINTR) continue;
    if (rc < 0) return -1;
    if (rc == 0) continue;  // re-check the deadline
    if ((p.revents & (POLLERR | POLLNVAL)) != 0 && (p.revents & events) == 0) {
      errno = EIO;
      return -1;
    }
    return 1;
  }
}

speed_t speed_of(int baud) {
  switch (baud) {
    case 300:
      return B300;
    case 600:
      return B600;
    case 1200:
      return B1200;
    case 2400:
      return B2400;
    case 4800:
      return B4800;
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    default:
      return B230400;
  }
}

}  // namespace

int FdLineWire::open(double timeout_s) {
  close();
  if (const auto* t = std::get_if<LineTcp>(&endpoint_)) return open_tcp(*t, timeout_s);
  return open_serial(std::get<LineSerial>(endpoint_));
}

int FdLineWire::open_tcp(const LineTcp& ep, double timeout_s) {
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICHOST;  // literals only (parse_line_endpoint): never a DNS wait
  addrinfo* found = nullptr;
  if (::getaddrinfo(ep.host.c_str(), std::to_string(ep.port).c_str(), &hints, &found) != 0) {
    errno = EHOSTUNREACH;
    return -1;
  }
  std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> list(found, &::freeaddrinfo);
  const auto deadline = deadline_after(timeout_s);
  int err = ECONNREFUSED;
  for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
    UniqueFd fd(::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
    if (!fd.valid()) continue;
    if (::connect(fd.get(), a->ai_addr, a->ai_addrlen) != 0) {
      if (errno != EINPROGRESS) {
        err = errno;
        continue;
      }
      if (wait_for(fd.get(), POLLOUT, deadline) != 1) {
        err = errno;
        continue;
      }
      socklen_t len = sizeof err;
      int so = 0;
      ::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &so, &len);
      if (so != 0) {
        err = so;
        continue;
      }
    }
    fd_ = std::move(fd);
    return 0;
  }
  errno = err;
  return -1;
}

int FdLineWire::open_serial(const LineSerial& ep) {
  UniqueFd fd(::open(ep.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
  if (!fd.valid()) return -1;
  termios tio{};
  if (::tcgetattr(fd.get(), &tio) != 0) return -1;
  ::cfmakeraw(&tio);
  ::cfsetspeed(&tio, speed_of(ep.baud));
  tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | PARODD | CSTOPB);
  tio.c_cflag |= (ep.data_bits == 7 ? CS7 : CS8) | CLOCAL | CREAD;
  if (ep.parity != 'N') tio.c_cflag |= PARENB | (ep.parity == 'O' ? PARODD : 0);
  if (ep.stop_bits == 2) tio.c_cflag |= CSTOPB;
  if (::tcsetattr(fd.get(), TCSANOW, &tio) != 0) return -1;
  fd_ = std::move(fd);
  return 0;
}

void FdLineWire::close() {
  fd_.reset();
  pending_.clear();
}

int FdLineWire::send(std::string_view bytes, double timeout_s) {
  if (!fd_.valid()) {
    errno = ENOTCONN;
    return -1;
  }
  const auto deadline = deadline_after(timeout_s);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::send(fd_.get(), bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == ENOTSOCK) {
      const ssize_t w = ::write(fd_.get(), bytes.data() + done, bytes.size() - done);
      if (w >= 0) {
        done += static_cast<std::size_t>(w);
        continue;
      }
    } else if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    } else if (n == 0) {
      errno = EAGAIN;  // nothing taken: wait for room, under the deadline
    }
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != ENOTSOCK) return -1;
    if (wait_for(fd_.get(), POLLOUT, deadline) != 1) return -1;
  }
  return static_cast<int>(done);
}

int FdLineWire::fill(Steady::time_point deadline) {
  for (;;) {
    if (wait_for(fd_.get(), POLLIN, deadline) != 1) return -1;
    char buf[512];
    const ssize_t n = ::read(fd_.get(), buf, sizeof buf);
    if (n == 0) {
      errno = ECONNRESET;  // the peer closed the connection
      return -1;
    }
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      return -1;
    }
    pending_.append(buf, static_cast<std::size_t>(n));
    return 0;
  }
}

int FdLineWire::receive(std::string& line, std::string_view terminator, double timeout_s,
                        std::size_t max_bytes) {
  if (!fd_.valid()) {
    errno = ENOTCONN;
    return -1;
  }
  const auto deadline = deadline_after(timeout_s);
  for (;;) {
    if (const auto end = pending_.find(terminator); end != std::string::npos) {
      if (end > max_bytes) {
        pending_.clear();
        errno = EMSGSIZE;
        return -1;
      }
      line = pending_.substr(0, end);
      pending_.erase(0, end + terminator.size());
      return static_cast<int>(line.size());
    }
    if (pending_.size() > max_bytes) {
      pending_.clear();
      errno = EMSGSIZE;
      return -1;
    }
    if (fill(deadline) == -1) return -1;
  }
}

int FdLineWire::receive_exact(std::string& bytes, std::size_t n, double timeout_s) {
  if (!fd_.valid()) {
    errno = ENOTCONN;
    return -1;
  }
  const auto deadline = deadline_after(timeout_s);
  while (pending_.size() < n) {
    if (fill(deadline) == -1) {
      // Part of it came, then the deadline: a reply cut short, not a silent device.
      if (errno == ETIMEDOUT && !pending_.empty()) errno = EBADMSG;
      return -1;
    }
  }
  bytes = pending_.substr(0, n);
  pending_.erase(0, n);
  return static_cast<int>(n);
}

void FdLineWire::flush() {
  pending_.clear();
  if (!fd_.valid()) return;
  // Bounded: a peer that streams without end cannot hold the caller here.
  char buf[512];
  for (int i = 0; i < 128 && ::read(fd_.get(), buf, sizeof buf) > 0; ++i) {
  }
}

}  // namespace station::drivers::ascii
