// Pre-run check of every configured device (issue 7 item 8).
#include "station/daemon/preflight.hpp"

#include <fmt/format.h>

namespace station {

namespace {

template <class R>
void note(std::vector<std::string>& out, const R& r, const std::string& device,
          const std::string& where) {
  if (!r) out.push_back(fmt::format("{} {}: {}", device, where, r.error().message));
}

void check_counters(Rig& rig, const StationConfig& c, std::vector<std::string>& out) {
  const auto tick = rig.counters->tick(0);
  if (!tick) {
    out.push_back(fmt::format("counter boards {}: {}", c.can_transport, tick.error().message));
    return;
  }
  for (const auto& slot : c.slots) {
    bool answered = false;
    for (const auto& r : tick.value().readings)
      answered = answered || (r.serial == slot.serial && r.answered);
    if (!answered) {
      out.push_back(fmt::format("counter board node {} ({}) on {}: no answer to SYNC", slot.node,
                                slot.serial, c.can_transport));
    }
  }
}

}  // namespace

std::vector<std::string> preflight(Rig& rig, const StationConfig& c) {
  std::vector<std::string> out;
  if (auto r = rig.chamber->connect(); !r) {
    note(out, r, "chamber", c.chamber.endpoint);
  } else {
    note(out, rig.chamber->read(), "chamber", c.chamber.endpoint);
  }
  if (rig.turntable) {
    if (auto r = rig.turntable->connect(); !r) {
      note(out, r, "turntable", c.turntable->endpoint);
    } else {
      note(out, rig.turntable->read(), "turntable", c.turntable->endpoint);
    }
  }
  check_counters(rig, c, out);
  if (rig.gpio) note(out, rig.gpio->open(), "gpio", c.gpio->chip);
  return out;
}

}  // namespace station
