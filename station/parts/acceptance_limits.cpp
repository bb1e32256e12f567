// [part."PN".acceptance]: the acceptance steps' limits.
#include "station/parts/acceptance_limits.hpp"

#include <fmt/format.h>

#include "station/config/toml_reader.hpp"

namespace station {
namespace {

using nlohmann::json;

// The maxima, each with its key: one list for reading, storing and reading back.
struct MaxKey {
  const char* key;
  std::optional<double> AcceptanceLimits::*field;
};
constexpr MaxKey kMaxima[] = {
    {"max_nonlinearity_ppm_fs", &AcceptanceLimits::max_nonlinearity_ppm_fs},
    {"max_asymmetry_ppm", &AcceptanceLimits::max_asymmetry_ppm},
    {"max_tilt_mrad", &AcceptanceLimits::max_tilt_mrad},
    {"max_turn_on_repeatability_dph", &AcceptanceLimits::max_turn_on_repeatability_dph},
    {"max_warmup_s", &AcceptanceLimits::max_warmup_s}};

}  // namespace

std::optional<AcceptanceLimits> read_acceptance_limits(const TomlView& part) {
  const auto t = part.opt_table("acceptance");
  if (!t) return std::nullopt;
  t->allow_only({"sf_pulse_per_arcsec", "sf_tc_ppm_per_c", "max_nonlinearity_ppm_fs",
                 "max_asymmetry_ppm", "max_tilt_mrad", "max_turn_on_repeatability_dph",
                 "max_warmup_s"});
  AcceptanceLimits a;
  a.sf_pulse_per_arcsec = read_range(*t, "sf_pulse_per_arcsec");
  a.sf_tc_ppm_per_c = read_range(*t, "sf_tc_ppm_per_c");
  for (const auto& m : kMaxima) {
    const auto x = t->opt_number(m.key);
    // A bound of zero or less would fail every gyro.
    if (x && !(*x > 0)) throw t->error(m.key, fmt::format("{} must be above 0", *x));
    a.*m.field = x;
  }
  return a;
}

json acceptance_limits_json(const AcceptanceLimits& a) {
  json j = json::object();
  if (a.sf_pulse_per_arcsec.min || a.sf_pulse_per_arcsec.max)
    j["sf_pulse_per_arcsec"] = range_json(a.sf_pulse_per_arcsec);
  if (a.sf_tc_ppm_per_c.min || a.sf_tc_ppm_per_c.max)
    j["sf_tc_ppm_per_c"] = range_json(a.sf_tc_ppm_per_c);
  for (const auto& m : kMaxima)
    if (a.*m.field) j[m.key] = *(a.*m.field);
  return j;
}

AcceptanceLimits acceptance_limits_from_json(const json& j) {
  AcceptanceLimits a;
  a.sf_pulse_per_arcsec = range_from_json(j, "sf_pulse_per_arcsec");
  a.sf_tc_ppm_per_c = range_from_json(j, "sf_tc_ppm_per_c");
  for (const auto& m : kMaxima)
    if (j.contains(m.key)) a.*m.field = j.at(m.key).get<double>();
  return a;
}

}  // namespace station
