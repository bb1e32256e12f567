// The meaning of a run's samples, and the one-line difference between two meanings.
#include "station/daemon/resume.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "compensation/earth_rate.hpp"

namespace station {

std::vector<RunSlot> run_slots_of(const StationConfig& c) {
  std::vector<RunSlot> out;
  for (std::size_t i = 0; i < c.slots.size(); ++i) {
    const auto& s = c.slots[i];
    out.push_back({static_cast<int>(i), s.node, s.serial, s.axis, s.pulse_weight_arcsec,
                   compensation::earth_rate_along_axis_dph(c.latitude_deg, s.enu),
                   s.gyro_given ? "start" : "config"});
  }
  return out;
}
namespace {

using nlohmann::json;

json meaning_of(const StationConfig& c) {
  json slots = json::array();
  for (std::size_t i = 0; i < c.slots.size(); ++i) {
    const auto& s = c.slots[i];
    slots.push_back(
        {{"slot", i},
         {"node", s.node},
         {"serial", s.serial},
         {"pulse_weight_arcsec", s.pulse_weight_arcsec},
         {"axis", s.axis},
         {"earth_rate_dph", compensation::earth_rate_along_axis_dph(c.latitude_deg, s.enu)}});
  }
  return {{"latitude_deg", c.latitude_deg},
          {"ref_temp_c", c.ref_temp_c},
          {"bin_s", c.bin_s},
          {"slots", slots}};
}

/// One line from an RFC 6902 patch between what the run stored and what the config says.
std::string describe_patch(const json& then, const json& patch) {
  std::string out;
  for (const auto& op : patch) {
    const std::string path = op.at("path").get<std::string>().substr(1);
    const std::string kind = op.at("op").get<std::string>();
    std::string part;
    if (kind == "replace") {
      part = fmt::format("{} {} -> {}", path, then.at(json::json_pointer(op.at("path"))).dump(),
                         op.at("value").dump());
    } else if (kind == "add") {
      part = fmt::format("{} added ({})", path, op.at("value").dump());
    } else {
      part = fmt::format("{} removed (was {})", path,
                         then.at(json::json_pointer(op.at("path"))).dump());
    }
    out += (out.empty() ? "" : "; ") + part;
  }
  return out;
}

/// Runs stored before migration 2 have no resolved meaning: compare their slots only.
std::string legacy_slot_mismatch(Store& store, const RunRecord& run, const StationConfig& config) {
  const auto stored = store.run_slots(run.id);
  std::string now, then;
  for (const auto& s : config.slots) now += fmt::format(" {}@{}", s.serial, s.node);
  for (const auto& s : stored) then += fmt::format(" {}@{}", s.serial, s.node);
  if (now == then) return {};
  return fmt::format("run {} was started with slots{} but the configuration has{}", run.id, then,
                     now);
}

}  // namespace

std::string resolved_meaning_json(const StationConfig& config) {
  return meaning_of(config).dump();
}

std::string resume_mismatch(Store& store, const RunRecord& run, const StationConfig& config) {
  json then;
  try {
    then = json::parse(run.resolved_json);
  } catch (const json::exception&) {
    throw InputError(fmt::format("{}: run {}: stored resolved configuration is not JSON",
                                 store.db().path(), run.id));
  }
  if (then.empty()) return legacy_slot_mismatch(store, run, config);
  const json patch = json::diff(then, meaning_of(config));
  if (patch.empty()) return {};
  return fmt::format("run {} was started with a different meaning of its samples: {}", run.id,
                     describe_patch(then, patch));
}

}  // namespace station
