// The start body's gyros: form checked here, meaning (slots, parts, serials twice) by the control.
#include "station/http/api_slots.hpp"

#include <fmt/format.h>

#include "station/common/text_rule.hpp"
#include "station/http/route_params.hpp"

namespace station::http {

namespace {

/// One slot's object {"serial", "part"?}; false with `error` set on a bad one.
bool read_gyro(const std::string& key, const nlohmann::json& v, SlotGyro& g, std::string& error) {
  const std::string where = fmt::format("field 'slots/{}", key);
  if (!v.is_object()) {
    error = where + "': expected an object {\"serial\": SERIAL, \"part\": PART}";
    return false;
  }
  for (const auto& [k, x] : v.items()) {
    if (k == "serial" || k == "part") continue;
    error = fmt::format("{}/{}': unknown (expected serial, part)", where, k.substr(0, 80));
    return false;
  }
  for (const char* name : {"serial", "part"}) {
    if (!v.contains(name)) continue;
    const auto& x = v[name];
    const auto problem = x.is_string() ? identifier_problem(x.get<std::string>())
                                       : std::optional<std::string>("expected a string");
    if (problem) {
      error = fmt::format("{}/{}': {}", where, name, *problem);
      return false;
    }
    (std::string(name) == "serial" ? g.serial : g.part) = x.get<std::string>();
  }
  if (g.serial.empty()) error = where + "/serial': required";
  return error.empty();
}

}  // namespace

std::vector<SlotGyro> slots_field(const nlohmann::json& body, std::string& error) {
  std::vector<SlotGyro> out;
  if (!body.contains("slots")) return out;
  const auto& slots = body["slots"];
  if (!slots.is_object()) {
    error = "field 'slots': expected an object {\"1\": {\"serial\": SERIAL, \"part\": PART}, ...}";
    return {};
  }
  for (const auto& [key, v] : slots.items()) {
    const auto n = slot_number(key);  // daemon/run_gyros.hpp: as --slot reads N
    if (!n) {
      error = fmt::format("field 'slots/{}': a slot is a number from 1", key.substr(0, 80));
      return {};
    }
    SlotGyro g{*n, "", ""};
    if (!read_gyro(key, v, g, error)) return {};
    out.push_back(std::move(g));
  }
  return out;
}

}  // namespace station::http
