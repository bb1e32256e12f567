// CAN transports carrying `struct can_frame` records: SocketCAN, AF_UNIX SEQPACKET, inherited fd.
#pragma once

#include <linux/can.h>

#include <chrono>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/common/clock.hpp"
#include "drivers/common/result.hpp"
#include "drivers/common/tap.hpp"
#include "drivers/common/unique_fd.hpp"

namespace station::drivers::can {

/// A CAN bus endpoint. Every call is bounded by a timeout; none blocks forever.
class CanTransport {
 public:
  virtual ~CanTransport() = default;
  /// Sends one frame; waits at most the send timeout for buffer space.
  virtual Result<void> send(const can_frame& frame) = 0;
  /// Receives one frame, blocking at most `timeout`; ErrorKind::timeout when none arrived.
  virtual Result<can_frame> receive(std::chrono::milliseconds timeout) = 0;
  /// The underlying descriptor, for the caller's poll loop (still owned by the transport).
  virtual int fd() const = 0;
  /// Receive time of the last frame, wall-clock seconds (kernel timestamp when available).
  virtual double last_rx_time_s() const = 0;
};

/// Which transport a spec string names.
enum class CanSpecKind { socketcan, unix_seqpacket, inherited_fd };

/// A parsed transport spec: `socketcan:IFACE`, `unix:PATH` or `fd:N`.
struct CanSpec {
  CanSpecKind kind = CanSpecKind::socketcan;
  std::string target;  ///< interface name, socket path, or the fd number as text
  int fd = -1;         ///< for inherited_fd
};

/// Options for opening a transport.
struct CanOpenOptions {
  std::vector<can_filter> filters;  ///< CAN_RAW_FILTER list (socketcan only); empty = all frames
  Tap* tap = nullptr;               ///< every frame in/out is reported here when set
  std::string tap_device = "can";   ///< device name in tap records
  std::chrono::milliseconds send_timeout{100};  ///< longest wait for send buffer space
  const Clock* clock = nullptr;  ///< time of the reconnect back-off (nullptr: steady clock)
};

/// Parses a spec string; throws std::invalid_argument naming the spec when malformed (config).
CanSpec parse_can_spec(std::string_view spec);

/// Opens the transport a spec names (does the I/O: socket/bind/connect). Errors name the spec.
Result<std::unique_ptr<CanTransport>> open_can_transport(const CanSpec& spec,
                                                         const CanOpenOptions& options = {});

/// Wraps an already-open descriptor carrying 16-byte can_frame records (takes ownership).
std::unique_ptr<CanTransport> make_fd_transport(UniqueFd fd, const CanOpenOptions& options = {},
                                                std::string name = "fd");

}  // namespace station::drivers::can
