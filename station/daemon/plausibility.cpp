// The one rule of plausible readings, applied to a rig's reading; episodes and their events.
#include "station/daemon/plausibility.hpp"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

namespace station {

namespace dr = station::drivers;

PlausibleRanges plausible_ranges(const Rig& rig) {
  PlausibleRanges r;
  r.air_c = rig.chamber ? rig.chamber->air_range_c() : dr::Chamber::kSensorRangeC;
  if (rig.turntable) r.rate_dps = rig.turntable->rate_range_dps();
  if (rig.turntable) r.angle_deg = rig.turntable->angle_range_deg();
  return r;
}

namespace {

// Safety decides what a break holds; here it only says the NaN is the chamber's own report.
bool sensor_break(const dr::ChamberState& c) {
  const dr::AlarmBits& a = c.alarms;
  return a.sensor_break;
}

}  // namespace

std::vector<Implausible> screen_reading(RigReading& r, const PlausibleRanges& ranges) {
  std::vector<Implausible> out;
  auto& chamber = r.chamber;
  // A NaN air with the sensor-break alarm is the chamber's report of its broken sensor.
  const bool broken = chamber && std::isnan(chamber->air_c) && sensor_break(*chamber);
  // One rule for each value: outside its range it is taken out (NaN) and reported.
  const auto take_out = [&out](const char* device, const char* quantity, double& v,
                               const dr::PlausibleRange& range) {
    if (const auto bound = dr::broken_bound(v, range)) {
      out.push_back({device, quantity, v, *bound});
      v = std::nan("");
    }
  };
  if (chamber && !broken) take_out("chamber", "air_c", chamber->air_c, ranges.air_c);
  // A NaN setpoint read-back stays the safety layer's (out of limits); any other is screened.
  if (chamber && !std::isnan(chamber->setpoint_c))
    take_out("chamber", "setpoint_c", chamber->setpoint_c, ranges.air_c);
  if (r.table) take_out("turntable", "angle_deg", r.table->angle_deg, ranges.angle_deg);
  if (r.table) {
    if (const auto bound = dr::broken_bound(r.table->rate_dps, ranges.rate_dps)) {
      out.push_back({"turntable", "rate_dps", r.table->rate_dps, *bound});
      r.table.reset();
      r.table_interlock_open.reset();
    }
  }
  return out;
}

namespace {

// JSON has no NaN or infinity: such a value is stored as null.
nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

EventNote started(const Implausible& f) {
  return {Severity::error,
          EventKind::implausible_reading,
          fmt::format("{} {} reads {} (bound {}): no such reading, kept empty", f.device,
                      f.quantity, f.value, f.bound),
          {{"device", f.device},
           {"quantity", f.quantity},
           {"value", number_or_null(f.value)},
           {"bound", number_or_null(f.bound)}}};
}

EventNote ended(const Implausible& f, long ticks) {
  return {Severity::info,
          EventKind::implausible_reading_end,
          fmt::format("{} {} plausible again after {} tick(s)", f.device, f.quantity, ticks),
          {{"device", f.device}, {"quantity", f.quantity}, {"ticks", ticks}}};
}

}  // namespace

std::vector<EventNote> PlausibilityWatch::observe(const std::vector<Implausible>& found,
                                                  bool chamber_read, bool table_read) {
  std::vector<EventNote> events;
  std::map<std::string, const Implausible*> now;
  for (const auto& f : found) now[f.device + " " + f.quantity] = &f;
  for (auto it = open_.begin(); it != open_.end();) {
    const bool read = it->second.first.device == "chamber" ? chamber_read : table_read;
    if (now.count(it->first) != 0 || !read) {
      ++it->second.ticks;  // still implausible, or no news (the device did not answer)
      ++it;
      continue;
    }
    events.push_back(ended(it->second.first, it->second.ticks));
    it = open_.erase(it);
  }
  for (const auto& [key, f] : now) {
    if (open_.count(key) != 0) continue;
    open_.emplace(key, Episode{*f, 1});
    events.push_back(started(*f));
  }
  return events;
}

}  // namespace station
