// Test helper: a proxy between libpq and the throw-away server (pg_server.hpp), listening on a
// Unix socket in a directory of its own (libpq's host=DIR connects to DIR/.s.PGSQL.5432) and
// forwarding bytes both ways on one thread, connection by connection (cancel requests too). Two
// hooks, real bytes otherwise: `on_client` sees each chunk a client sends before it is forwarded
// (a test freezes the backend when the forwarder starts a COPY), and `swallow_replies_after`
// drops the server's replies to a connection once its client has sent the given bytes (a COMMIT
// the server executes whose answer never reaches the client).
#pragma once

#include <fmt/format.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace station::testing_support {

class PgProxy {
 public:
  /// Forwards to the server whose socket directory is `server_dir`.
  explicit PgProxy(std::string server_dir) : server_dir_(std::move(server_dir)) {
    char tmpl[] = "/tmp/station-pgproxy-XXXXXX";
    dir_ = mkdtemp(tmpl);
    listen_fd_ = unix_socket(dir_, true);
    thread_ = std::thread([this] { loop(); });
  }
  ~PgProxy() {
    stop_ = true;
    thread_.join();
    for (auto& p : pairs_) close_pair(p);
    ::close(listen_fd_);
    std::filesystem::remove_all(dir_);
  }
  PgProxy(const PgProxy&) = delete;
  PgProxy& operator=(const PgProxy&) = delete;

  std::string url(const std::string& db) const {
    return fmt::format("postgresql:///{}?host={}&user=station", db, dir_);
  }
  const std::string& dir() const { return dir_; }
  /// Called (on the proxy's thread) with each chunk a client sends, before it is forwarded.
  void on_client(std::function<void(std::string_view)> f) {
    std::lock_guard lock(mu_);
    on_client_ = std::move(f);
  }
  void swallow_replies_after(std::string bytes) {
    std::lock_guard lock(mu_);
    swallow_after_ = std::move(bytes);
  }
  /// Closes every connection (from any thread): a client waiting on an answer sees the end.
  void cut() { cut_ = true; }

 private:
  struct Pair {
    int client = -1, server = -1;
    bool swallow = false;
  };

  static int unix_socket(const std::string& dir, bool listen) {
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    const std::string path = dir + "/.s.PGSQL.5432";
    path.copy(a.sun_path, sizeof a.sun_path - 1);
    const auto* sa = reinterpret_cast<const sockaddr*>(&a);
    const bool ok = listen ? ::bind(fd, sa, sizeof a) == 0 && ::listen(fd, 16) == 0
                           : ::connect(fd, sa, sizeof a) == 0;
    if (!ok) throw std::runtime_error("proxy socket " + path);
    return fd;
  }
  static void close_pair(Pair& p) {
    if (p.client >= 0) ::close(p.client);
    if (p.server >= 0) ::close(p.server);
    p.client = p.server = -1;
  }
  static bool send_all(int fd, const char* data, std::size_t n) {
    while (n > 0) {
      const ssize_t w = ::send(fd, data, n, MSG_NOSIGNAL);
      if (w <= 0) return false;
      data += w;
      n -= static_cast<std::size_t>(w);
    }
    return true;
  }
  // One chunk from `from`; false when the pair is done.
  bool relay(Pair& p, bool from_client) {
    char buf[65536];
    const ssize_t n = ::recv(from_client ? p.client : p.server, buf, sizeof buf, 0);
    if (n <= 0) return false;
    const std::string_view chunk(buf, static_cast<std::size_t>(n));
    if (!from_client) return p.swallow || send_all(p.client, buf, chunk.size());
    std::function<void(std::string_view)> hook;
    {
      std::lock_guard lock(mu_);
      hook = on_client_;
      if (!swallow_after_.empty() && chunk.find(swallow_after_) != std::string_view::npos)
        p.swallow = true;
    }
    if (hook) hook(chunk);
    return send_all(p.server, buf, chunk.size());
  }
  void loop() {
    while (!stop_) {
      if (cut_.exchange(false)) {
        for (auto& p : pairs_) close_pair(p);
        pairs_.clear();
      }
      std::vector<pollfd> fds = {{listen_fd_, POLLIN, 0}};
      for (const auto& p : pairs_) {
        fds.push_back({p.client, POLLIN, 0});
        fds.push_back({p.server, POLLIN, 0});
      }
      if (::poll(fds.data(), fds.size(), 50) <= 0) continue;
      if (fds[0].revents & POLLIN) {
        Pair p;
        p.client = ::accept(listen_fd_, nullptr, nullptr);
        p.server = unix_socket(server_dir_, false);
        pairs_.push_back(p);
        continue;
      }
      for (std::size_t i = 0; i < fds.size() / 2; ++i) {
        auto& p = pairs_[i];
        const bool c = fds[1 + 2 * i].revents != 0, s = fds[2 + 2 * i].revents != 0;
        if ((c && !relay(p, true)) || (s && !relay(p, false))) close_pair(p);
      }
      std::erase_if(pairs_, [](const Pair& p) { return p.client < 0; });
    }
  }

  std::string server_dir_, dir_;
  int listen_fd_ = -1;
  std::vector<Pair> pairs_;
  std::mutex mu_;
  std::function<void(std::string_view)> on_client_;
  std::string swallow_after_;
  std::atomic<bool> stop_{false}, cut_{false};
  std::thread thread_;
};

/// The simple-query message of `sql` as libpq sends it ('Q', length, text, NUL).
inline std::string query_message(const std::string& sql) {
  const auto n = static_cast<std::uint32_t>(sql.size() + 5);
  std::string m = "Q";
  for (int shift : {24, 16, 8, 0}) m += static_cast<char>((n >> shift) & 0xFF);
  return m + sql + '\0';
}

}  // namespace station::testing_support
