// RTU framing: CRC-16 and silence-delimited frame reads.
#include "sim_devices/servers/rtu_framing.hpp"

#include <poll.h>
#include <unistd.h>

namespace station::sim {

std::uint16_t modbus_crc16(std::span<const std::uint8_t> bytes) {
  std::uint16_t crc = 0xFFFF;
  for (std::uint8_t b : bytes) {
    crc ^= b;
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) ? (crc >> 1) ^ 0xA001 : crc >> 1;
  }
  return crc;
}

int read_rtu_frame(int fd, std::uint8_t* buf, int cap, int silence_ms) {
  int len = 0;
  while (len < cap) {
    const ssize_t n = ::read(fd, buf + len, static_cast<std::size_t>(cap - len));
    if (n <= 0) break;
    len += static_cast<int>(n);
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, silence_ms) <= 0 || !(p.revents & POLLIN)) break;  // end of frame
  }
  return len;
}

bool rtu_frame_ok(std::span<const std::uint8_t> frame) {
  // Unit id, function code and the two CRC bytes at least.
  if (frame.size() < 4) return false;
  const std::uint16_t crc = modbus_crc16(frame.first(frame.size() - 2));
  // The CRC goes low byte first (spec 6.2.2).
  return frame[frame.size() - 2] == (crc & 0xFF) && frame[frame.size() - 1] == (crc >> 8);
}

}  // namespace station::sim
