// LineServer: a poll()-driven thread serving request lines over TCP or a pty master.
#include "sim_devices/servers/line_server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace station::sim {
namespace {

[[noreturn]] void sys_fail(const std::string& what) {
  throw std::runtime_error("line server: " + what + ": " + std::strerror(errno));
}

int listen_on(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd == -1) sys_fail("socket");
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == -1 || ::listen(fd, 8) == -1) {
    ::close(fd);
    sys_fail("bind/listen 127.0.0.1:" + std::to_string(port));
  }
  return fd;
}

void write_all(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    // A socket never raises SIGPIPE at a client that went away (MSG_NOSIGNAL); a pty is written.
    ssize_t n = ::send(fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == ENOTSOCK) n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && (errno == EINTR || errno == EAGAIN)) {
      pollfd p{fd, POLLOUT, 0};
      if (::poll(&p, 1, 100) <= 0) return;
    } else {
      return;
    }
  }
}

}  // namespace

LineServer::~LineServer() {
  stop();
}

void LineServer::start_tcp(int port) {
  listen_fd_ = listen_on(port);
  sockaddr_in a{};
  socklen_t len = sizeof a;
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len);
  port_ = ntohs(a.sin_port);
  tcp_ = listening_ = true;
  thread_ = std::thread([this] { run(); });
}

void LineServer::start_pty(int baud) {
  baud_ = baud;
  pty_master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC | O_NONBLOCK);
  if (pty_master_ == -1) sys_fail("posix_openpt");
  if (::grantpt(pty_master_) == -1 || ::unlockpt(pty_master_) == -1) sys_fail("grantpt");
  char name[128];
  if (::ptsname_r(pty_master_, name, sizeof name) != 0) sys_fail("ptsname_r");
  pty_path_ = name;
  // Held open so the master never reads a hang-up between clients.
  pty_slave_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (pty_slave_ == -1) sys_fail("open " + pty_path_);
  clients_[pty_master_] = {};
  thread_ = std::thread([this] { run(); });
}

void LineServer::stop() {
  stop_ = true;
  tcp_ = false;  // nothing to settle any more
  if (thread_.joinable()) thread_.join();
  for (auto& [fd, buf] : clients_)
    if (fd != pty_master_) ::close(fd);
  clients_.clear();
  for (int* fd : {&listen_fd_, &pty_master_, &pty_slave_}) {
    if (*fd != -1) ::close(*fd);
    *fd = -1;
  }
}

std::string LineServer::endpoint() const {
  if (!pty_path_.empty()) return "serial:" + pty_path_ + "?baud=" + std::to_string(baud_);
  return "tcp://127.0.0.1:" + std::to_string(port_);
}

// Applies an injected disconnect (TCP): drops clients and listener, listens again on the same
// port when the down time is over. False while down.
bool LineServer::link_up() {
  if (pty_master_ != -1) return true;
  double down_until = 0;
  const std::uint64_t asked = faults_.kicks(down_until);
  if (asked != kicks_applied_.load()) {
    for (auto& [fd, buf] : clients_) ::close(fd), drips_.forget(fd);
    clients_.clear();
    if (listen_fd_ != -1) ::close(listen_fd_);
    listen_fd_ = -1;
    listening_ = false;
    kicks_applied_ = asked;
  }
  if (listen_fd_ != -1) return true;
  if (faults_.now_s() < down_until) return false;
  try {
    listen_fd_ = listen_on(port_);
  } catch (const std::runtime_error&) {
    return false;  // the port is still in TIME_WAIT somewhere: try again next turn
  }
  listening_ = true;
  return true;
}

// Reads what `fd` has, answers every complete line. `close_it` when the peer went away or a
// drop was injected.
void LineServer::serve_bytes(int fd, std::string& buffer, bool& close_it) {
  char chunk[512];
  const ssize_t n = ::read(fd, chunk, sizeof chunk);
  // EIO on the pty master is a slave side with no reader between clients: wait. Anything else
  // that is not "try again" ends a socket client.
  const bool pty_idle = n < 0 && errno == EIO && fd == pty_master_;
  if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR && !pty_idle)) {
    close_it = fd != pty_master_;
    return;
  }
  if (n < 0) return;
  buffer.append(chunk, static_cast<std::size_t>(n));
  const std::string term = device_.request_terminator();
  for (auto end = buffer.find(term); end != std::string::npos; end = buffer.find(term)) {
    const std::string request = buffer.substr(0, end);
    buffer.erase(0, end + term.size());
    ++requests_;
    int code = 0;
    switch (faults_.take(code)) {
      case FaultSchedule::Fault::timeout:
        continue;
      case FaultSchedule::Fault::drop:
        close_it = fd != pty_master_;
        if (close_it) return;
        continue;
      case FaultSchedule::Fault::exception:
        reply(fd, device_.encode(device_.error_reply(request, code)));
        continue;
      case FaultSchedule::Fault::none:
        break;
    }
    if (auto r = device_.handle(request)) reply(fd, device_.encode(std::move(*r)));
  }
  if (buffer.size() > kMaxLine) buffer.clear();
}

void LineServer::reply(int fd, const std::string& bytes) {
  const double interval_s = faults_.drip_interval_s();
  if (interval_s <= 0 && !drips_.busy(fd)) return write_all(fd, bytes);
  drips_.push(fd, {reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()}, interval_s);
}

void LineServer::run() {
  while (!stop_) {
    const bool up = link_up();
    std::vector<pollfd> fds;
    if (up && listen_fd_ != -1) fds.push_back({listen_fd_, POLLIN, 0});
    for (auto& [fd, buf] : clients_) fds.push_back({fd, POLLIN, 0});
    const int ready = ::poll(fds.data(), fds.size(), drips_.poll_ms(50));
    drips_.send_due();
    if (ready <= 0) continue;
    for (const auto& p : fds) {
      if (p.revents == 0) continue;
      if (p.fd == listen_fd_) {
        const int c = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
        if (c != -1) {
          clients_[c] = {};
        } else if (errno == EMFILE || errno == ENFILE || errno == ENOMEM) {
          std::this_thread::sleep_for(std::chrono::milliseconds(50));  // no spin on a full table
        }
        continue;
      }
      auto it = clients_.find(p.fd);
      if (it == clients_.end()) continue;
      bool close_it = false;
      serve_bytes(p.fd, it->second, close_it);
      if (close_it) {
        drips_.forget(p.fd);
        ::close(p.fd);
        clients_.erase(it);
      }
    }
  }
}

}  // namespace station::sim
