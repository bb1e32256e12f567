// Limit ranges: read, stored, read back.
#include "station/parts/limit_range.hpp"

#include <fmt/format.h>

#include "station/config/toml_reader.hpp"

namespace station {

using nlohmann::json;

LimitRange read_range(const TomlView& part, std::string_view key) {
  const auto t = part.opt_table(key);
  if (!t) return {};
  t->allow_only({"min", "max"});
  LimitRange r{t->opt_number("min"), t->opt_number("max")};
  if (!r.min && !r.max) throw part.error(key, "give min, max or both");
  if (r.min && r.max && *r.min > *r.max) {
    throw t->error("min", fmt::format("min {} is above max {}", *r.min, *r.max));
  }
  return r;
}

json range_json(const LimitRange& r) {
  json j = json::object();
  if (r.min) j["min"] = *r.min;
  if (r.max) j["max"] = *r.max;
  return j;
}

LimitRange range_from_json(const json& j, const char* key) {
  if (!j.contains(key)) return {};
  const json& r = j.at(key);
  LimitRange out;
  if (r.contains("min")) out.min = r.at("min").get<double>();
  if (r.contains("max")) out.max = r.at("max").get<double>();
  return out;
}

}  // namespace station
