// Wall-clock stamping for tap records.
#include "drivers/common/tap.hpp"

#include <ctime>

namespace station::drivers {

double tap_wall_time_s() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::vector<std::uint8_t> errno_bytes(int err) {
  const auto u = static_cast<std::uint32_t>(err);
  return {static_cast<std::uint8_t>(u >> 24), static_cast<std::uint8_t>(u >> 16),
          static_cast<std::uint8_t>(u >> 8), static_cast<std::uint8_t>(u)};
}

int errno_of_bytes(std::span<const std::uint8_t, 4> b) {
  return static_cast<int>(std::uint32_t{b[0]} << 24 | std::uint32_t{b[1]} << 16 |
                          std::uint32_t{b[2]} << 8 | b[3]);
}

}  // namespace station::drivers
