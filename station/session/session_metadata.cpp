// session.toml's derived keys re-derived (see session_metadata.hpp).
#include "station/session/session_metadata.hpp"

#include <toml++/toml.h>

#include "station/daemon/resume.hpp"

namespace station {
namespace {

using nlohmann::json;

json toml_value(const toml::node* n) {
  if (n == nullptr) return nullptr;
  if (const auto* s = n->as_string()) return s->get();
  if (const auto* i = n->as_integer()) return i->get();
  if (const auto* f = n->as_floating_point()) return f->get();
  if (const auto* b = n->as_boolean()) return b->get();
  return "(not a value)";
}

json slots_json(const std::vector<RunSlot>& slots) {
  json out = json::array();
  for (const auto& s : slots)
    out.push_back({{"slot", s.slot},
                   {"node", s.node},
                   {"serial", s.serial},
                   {"axis", s.axis},
                   {"pulse_weight_arcsec", s.pulse_weight_arcsec},
                   {"earth_rate_dph", s.earth_rate_dph}});
  return out;
}

json recorded_slots(const toml::table& t) {
  json out = json::array();
  const auto* list = t["slot"].as_array();
  if (list == nullptr) return out;
  for (const auto& node : *list) {
    json s = json::object();
    if (const auto* tbl = node.as_table())
      for (const auto& [key, value] : *tbl) s[std::string(key.str())] = toml_value(&value);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace

std::optional<json> header_difference(const std::string& path, const StationConfig& config,
                                      const Protocol& protocol) {
  const toml::table t = toml::parse_file(path);
  const std::vector<std::pair<std::string, json>> derived{
      {"station", config.name},
      {"latitude_deg", config.latitude_deg},
      {"protocol_name", protocol.name},
      {"resolved_json", resolved_meaning_json(config)},
      {"slot", slots_json(run_slots_of(config))}};
  for (const auto& [key, replayed] : derived) {
    const json recorded = key == "slot" ? recorded_slots(t) : toml_value(t.get(key));
    if (recorded == replayed) continue;
    return json{{"at", {{"file", path}, {"key", key}}},
                {"quantity", "session.toml " + key},
                {"recorded", recorded},
                {"replayed", replayed}};
  }
  return std::nullopt;
}

}  // namespace station
