// Resume decisions: same meaning of every sample, stored protocol, explicit abort of superseded
// runs.
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
                   compensation::earth_rate_along_axis_dph(c.latitude_deg, s.enu)});
  }
  return out;
}
namespace {

using nlohmann::json;

void abort_run(Store& store, const RunRecord& run, const std::string& why) {
  store.add_event(run.id, run.last_tick_s.value_or(0), Severity::warn, "seq", EventKind::aborted,
                  why);
  store.finish_run(run.id, RunState::aborted);
}

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

ResumeDecision decide_resume(Store& store, const StationConfig& config, bool fresh,
                             bool abort_mismatch) {
  ResumeDecision d;
  auto run = store.find_unfinished_run();
  if (!run) return d;
  if (fresh) {
    abort_run(store, *run, "superseded by a new run (--new)");
    return d;
  }
  if (const auto why = resume_mismatch(store, *run, config); !why.empty()) {
    if (!abort_mismatch) {
      throw InputError(
          fmt::format("{}: {}; start a new run with --new (the old one is then "
                      "marked aborted)",
                      store.db().path(), why));
    }
    abort_run(store, *run, why);
    return d;
  }
  d.protocol = parse_protocol(run->protocol_text,
                              fmt::format("{}:run {} protocol", store.db().path(), run->id));
  d.run = std::move(run);
  return d;
}

}  // namespace station
