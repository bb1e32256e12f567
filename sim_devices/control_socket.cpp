// ControlSocket: poll() over the listener and its clients, line splitting, one reply per line.
#include "sim_devices/control_socket.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace station::sim {
namespace {

sockaddr_un unix_address(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof(addr.sun_path))
    throw std::runtime_error(fmt::format("control socket '{}': path empty or too long", path));
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  return addr;
}

int connect_unix(const std::string& path) {
  const sockaddr_un addr = unix_address(path);
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

// Removes a stale socket at `path`; refuses anything that is not one, or one still served.
void clear_stale(const std::string& path) {
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) return;  // nothing there
  if (!S_ISSOCK(st.st_mode))
    throw std::runtime_error(fmt::format("control socket {}: exists and is not a socket", path));
  if (const int fd = connect_unix(path); fd >= 0) {
    close(fd);
    throw std::runtime_error(fmt::format("control socket {}: another process listens on it", path));
  }
  unlink(path.c_str());
}

bool send_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t n = send(fd, text.data(), text.size(), MSG_NOSIGNAL);
    if (n <= 0) return false;
    text.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

}  // namespace

ControlSocket::ControlSocket(std::string path, Handler handler)
    : path_(std::move(path)), handler_(std::move(handler)) {
  const sockaddr_un addr = unix_address(path_);
  clear_stale(path_);
  listen_fd_ = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0 || bind(listen_fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) ||
      listen(listen_fd_, 4) != 0) {
    const int err = errno;
    if (listen_fd_ >= 0) close(listen_fd_);
    throw std::runtime_error(fmt::format("control socket {}: {}", path_, std::strerror(err)));
  }
}

ControlSocket::~ControlSocket() {
  for (const Client& c : clients_) close(c.fd);
  close(listen_fd_);
  unlink(path_.c_str());
}

int ControlSocket::service(int timeout_ms) {
  std::vector<pollfd> fds{{listen_fd_, POLLIN, 0}};
  for (const Client& c : clients_) fds.push_back({c.fd, POLLIN, 0});
  answered_ = 0;
  if (poll(fds.data(), fds.size(), timeout_ms) <= 0) return 0;
  // Clients first (indices match fds[1..]); a new one joins after them.
  std::vector<Client> kept;
  for (std::size_t i = 0; i < clients_.size(); ++i) {
    if (fds[i + 1].revents == 0 || serve_client(clients_[i])) {
      kept.push_back(std::move(clients_[i]));
    } else {
      close(clients_[i].fd);
    }
  }
  clients_ = std::move(kept);
  if (fds[0].revents & POLLIN) {
    const int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd >= 0) clients_.push_back({fd, {}});
  }
  return answered_;
}

// Reads what is there and answers each complete line; false when the client is to be dropped.
bool ControlSocket::serve_client(Client& c) {
  char buf[512];
  const ssize_t n = recv(c.fd, buf, sizeof buf, MSG_DONTWAIT);
  if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) return false;
  if (n > 0) c.pending.append(buf, static_cast<std::size_t>(n));
  std::size_t nl;
  while ((nl = c.pending.find('\n')) != std::string::npos) {
    std::string line = c.pending.substr(0, nl);
    c.pending.erase(0, nl + 1);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::string reply = handler_(line);
    ++answered_;
    if (!send_all(c.fd, reply + "\n")) return false;
  }
  if (c.pending.size() > kMaxControlLine) {
    send_all(c.fd, fmt::format("error: line longer than {} bytes\n", kMaxControlLine));
    return false;
  }
  return true;
}

std::vector<std::string> send_control_commands(const std::string& path,
                                               const std::vector<std::string>& commands,
                                               int timeout_ms) {
  const int fd = connect_unix(path);
  if (fd < 0)
    throw std::runtime_error(fmt::format("control socket {}: {}", path, std::strerror(errno)));
  std::vector<std::string> replies;
  std::string pending;
  for (const std::string& cmd : commands) {
    if (!send_all(fd, cmd + "\n")) {
      close(fd);
      throw std::runtime_error(fmt::format("control socket {}: connection lost", path));
    }
    std::size_t nl;
    while ((nl = pending.find('\n')) == std::string::npos) {
      pollfd p{fd, POLLIN, 0};
      char buf[512];
      const ssize_t n = poll(&p, 1, timeout_ms) > 0 ? recv(fd, buf, sizeof buf, 0) : -1;
      if (n <= 0) {
        close(fd);
        throw std::runtime_error(
            fmt::format("control socket {}: no reply to '{}' within {} ms", path, cmd, timeout_ms));
      }
      pending.append(buf, static_cast<std::size_t>(n));
    }
    replies.push_back(pending.substr(0, nl));
    pending.erase(0, nl + 1);
  }
  close(fd);
  return replies;
}

}  // namespace station::sim
