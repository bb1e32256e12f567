// One point every transport exchange passes through, with its timestamp, so a session can be
// recorded and later replayed through the same drivers (gpsd's device logs).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace station::drivers {

/// Direction of one exchange as seen from the station.
enum class TapDirection : std::uint8_t { tx, rx, event };

/// One exchange on one transport.
struct TapRecord {
  double wall_time_s = 0;  ///< CLOCK_REALTIME seconds since the Unix epoch
  std::string device;      ///< transport name, e.g. "chamber", "can0", "gpio"
  TapDirection direction = TapDirection::tx;
  std::string kind;                 ///< "modbus-read", "modbus-write", "can", "gpio-edge", "error"
  std::vector<std::uint8_t> bytes;  ///< wire payload: CAN frame (16 bytes), Modbus PDU, line value
  std::string detail;               ///< human-readable summary (addresses, counts, error text)
};

/// Receives every exchange. Implementations must be cheap and must not throw.
class Tap {
 public:
  virtual ~Tap() = default;
  virtual void on_exchange(const TapRecord& record) noexcept = 0;
};

/// A failure's errno (libmodbus's EMB* codes included) as 4 big-endian bytes, and back: the
/// payload of an "error" event record on every transport, so replay fails the same way.
std::vector<std::uint8_t> errno_bytes(int err);
int errno_of_bytes(std::span<const std::uint8_t, 4> bytes);

/// Wall-clock seconds (CLOCK_REALTIME) for stamping tap records.
double tap_wall_time_s();

}  // namespace station::drivers
