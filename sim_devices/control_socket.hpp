// A local control socket (unix stream): text commands, one per line, each answered by one reply
// line. simrig serves its fault commands on it; send_control_commands() is the client side.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace station::sim {

/// Longest command line accepted, bytes; a longer one is answered with an error and the client
/// is disconnected.
inline constexpr std::size_t kMaxControlLine = 1024;

/// The listening side. Not thread-safe: service() runs the handler on the caller's thread.
class ControlSocket {
 public:
  /// Turns one command line (without its newline) into one reply line (without newline).
  using Handler = std::function<std::string(std::string_view line)>;

  /// Listens on `path`. A stale socket there is replaced; anything else at `path` (a file, a
  /// directory, a socket another process listens on) is refused with std::runtime_error.
  ControlSocket(std::string path, Handler handler);
  /// Closes every connection and removes the socket file.
  ~ControlSocket();
  ControlSocket(const ControlSocket&) = delete;
  ControlSocket& operator=(const ControlSocket&) = delete;

  /// Waits up to timeout_ms for a connection or input, accepts, and answers every complete
  /// line received; returns the number of commands answered.
  int service(int timeout_ms);
  const std::string& path() const { return path_; }

 private:
  struct Client {
    int fd;
    std::string pending;  // bytes after the last newline
  };
  bool serve_client(Client& c);

  std::string path_;
  Handler handler_;
  int listen_fd_ = -1;
  std::vector<Client> clients_;
  int answered_ = 0;
};

/// Connects to a control socket, sends each command and collects one reply line per command,
/// waiting at most timeout_ms for each. Throws std::runtime_error naming `path` when it cannot
/// connect or a reply does not come.
std::vector<std::string> send_control_commands(const std::string& path,
                                               const std::vector<std::string>& commands,
                                               int timeout_ms = 2000);

}  // namespace station::sim
