// A line-oriented ASCII device server (ESPEC P300, ACUTROL3000 faces) over TCP on 127.0.0.1 or a
// pty standing in for the serial line, with the same fault injection as ModbusServer.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "sim_devices/servers/drip_queue.hpp"
#include "sim_devices/servers/fault_schedule.hpp"
#include "sim_devices/servers/sim_server.hpp"

namespace station::sim {

/// A device that answers command lines. Called from the server thread only.
class LineDevice {
 public:
  virtual ~LineDevice() = default;
  /// Ends every request line (a trailing CR is the device's to strip) / every reply.
  virtual std::string request_terminator() const = 0;
  virtual std::string reply_terminator() const = 0;
  /// The reply to one request (terminator removed); nullopt: the device stays silent.
  virtual std::optional<std::string> handle(std::string_view request) = 0;
  /// The reply the device gives when it fails a request (an injected exception `code`).
  virtual std::string error_reply(std::string_view request, int code) = 0;
  /// The bytes that carry a reply on the wire: by default the reply and reply_terminator(); a
  /// device with a framing of its own (a length-prefixed header) says so here.
  virtual std::string encode(std::string reply) const { return reply + reply_terminator(); }
};

/// Serves one LineDevice. start_*() spawns the thread; the destructor stops and joins it.
class LineServer final : public SimServer {
 public:
  /// Stores the device (not owned; must outlive the server); no I/O.
  explicit LineServer(LineDevice& device) : device_(device) {}
  ~LineServer() override;
  LineServer(const LineServer&) = delete;
  LineServer& operator=(const LineServer&) = delete;

  /// Listens on 127.0.0.1:port (0 = ephemeral) and serves; throws std::runtime_error.
  void start_tcp(int port = 0);
  /// Opens a pty pair and serves on its master; clients open pty_path(). Throws on failure.
  void start_pty(int baud = 9600);
  void stop() override;

  int port() const { return port_; }
  const std::string& pty_path() const { return pty_path_; }
  /// tcp://127.0.0.1:PORT or serial:/dev/pts/N?baud=B.
  std::string endpoint() const override;
  std::uint64_t requests() const override { return requests_.load(); }

  /// Longest request line kept; a longer one is discarded unanswered (as a device's buffer).
  static constexpr std::size_t kMaxLine = 1024;

 private:
  void run();
  bool link_up();
  void serve_bytes(int fd, std::string& buffer, bool& close_it);
  /// Sends a reply's bytes: at once, or a byte at a time while a drip is on (or behind one).
  void reply(int fd, const std::string& bytes);

  LineDevice& device_;
  int listen_fd_ = -1, pty_master_ = -1, pty_slave_ = -1, port_ = 0, baud_ = 9600;
  std::string pty_path_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> requests_{0};
  std::thread thread_;
  std::map<int, std::string> clients_;  // fd -> bytes of a partial line
  DripQueue drips_;
};

}  // namespace station::sim
