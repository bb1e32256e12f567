// Reading and writing can-utils' candump log format: "(1700000000.123456) can0 080#05".
#pragma once

#include <linux/can.h>

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/common/result.hpp"
#include "drivers/common/tap.hpp"

namespace station::drivers::can {

/// One line of a candump log.
struct CandumpRecord {
  std::int64_t time_sec = 0;    ///< wall-clock seconds since the Unix epoch
  std::uint32_t time_usec = 0;  ///< microseconds 0..999999
  std::string interface;        ///< e.g. "can0"
  can_frame frame{};            ///< classic CAN frame; CAN_EFF_FLAG/CAN_RTR_FLAG as logged
};

/// Formats one record as a candump -l line (no newline): 3 hex ID digits, 8 when extended.
std::string format_candump_line(const CandumpRecord& record);

/// Parses one candump -l line; protocol error saying what is malformed.
Result<CandumpRecord> parse_candump_line(std::string_view line);

/// Writes records as candump -l lines; throws std::runtime_error naming the path on failure.
void write_candump_log(const std::string& path, const std::vector<CandumpRecord>& records);

/// Reads a candump log (blank lines skipped); throws std::runtime_error "path:line: what".
std::vector<CandumpRecord> read_candump_log(const std::string& path);

/// A Tap that appends every CAN frame (kind "can", 16 bytes) to a stream in candump -l format.
class CandumpTap final : public Tap {
 public:
  /// Writes to `out` (not owned, must outlive the tap), naming the bus `interface`; stamps each
  /// line with `now_s()` (seconds since the Unix epoch on the run's clock) or, without it, the
  /// record's wall time.
  CandumpTap(std::ostream& out, std::string interface, std::function<double()> now_s = {});
  void on_exchange(const TapRecord& record) noexcept override;

 private:
  std::mutex mutex_;
  std::ostream& out_;
  std::string interface_;
  std::function<double()> now_s_;
};

}  // namespace station::drivers::can
