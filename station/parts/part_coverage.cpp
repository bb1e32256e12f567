// Which gyros of a run a part file judges (part_coverage.hpp).
#include "station/parts/part_coverage.hpp"

#include <fmt/format.h>

#include "station/common/logging.hpp"

namespace station {

std::vector<std::string> slots_without_part(const StationConfig& config,
                                            const std::string& parts_path) {
  const std::string& path = parts_path.empty() ? config.parts_path : parts_path;
  std::vector<std::string> out;
  if (path.empty()) return out;
  for (std::size_t i = 0; i < config.slots.size(); ++i) {
    const auto& s = config.slots[i];
    if (!s.part.empty()) continue;
    out.push_back(fmt::format(
        "{}: slot {} (node {}, serial {}) names no part: no part limits, no verdict (name one: "
        "--slot {}={},PART or [[slot]] part = \"PART\")",
        path, i + 1, s.node, s.serial.empty() ? "?" : s.serial, i + 1,
        s.serial.empty() ? "SERIAL" : s.serial));
  }
  return out;
}

void warn_slots_without_part(const StationConfig& config, const std::string& parts_path) {
  for (const auto& line : slots_without_part(config, parts_path)) log("seq")->warn("{}", line);
}

}  // namespace station
