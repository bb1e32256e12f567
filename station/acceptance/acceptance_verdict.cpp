// Acceptance figures against a part's limits.
#include "station/acceptance/acceptance_verdict.hpp"

#include <fmt/format.h>

#include <cmath>

#include "station/common/number_text.hpp"
#include "station/store/acceptance_results.hpp"

namespace station {
namespace {

using nlohmann::json;

/// One verdict being built: each limit checked, each failure in words.
struct Judge {
  int checked = 0;
  json failed = json::array();
  json not_judged = json::array();  ///< figures stated but not judged, with why

  void range(const std::string& what, const json& value, const LimitRange& r, const char* unit) {
    if (!r.min && !r.max) return;
    ++checked;
    if (!value.is_number()) {
      failed.push_back(what + " not measured");
      return;
    }
    const double v = value;
    if (r.min && v < *r.min)
      failed.push_back(fmt::format("{} {} {} below {}", what, beside_limit(v, *r.min, 7), unit,
                                   as_written(*r.min)));
    if (r.max && v > *r.max)
      failed.push_back(fmt::format("{} {} {} above {}", what, beside_limit(v, *r.max, 7), unit,
                                   as_written(*r.max)));
  }
  void at_most(const std::string& what, const json& value, const std::optional<double>& max,
               const char* unit) {
    if (!max) return;
    ++checked;
    if (!value.is_number())
      failed.push_back(what + " not measured");
    else if (const double v = value.get<double>(); std::abs(v) > *max)
      failed.push_back(fmt::format("{} {} {} above {}", what,
                                   beside_limit(v, v < 0 ? -*max : *max, 4), unit,
                                   as_written(*max)));
  }
};

json figure(const json& obj, const char* key) {
  return obj.is_object() && obj.value("ok", false) && obj.contains(key) ? obj[key] : json();
}

void judge_each(Judge& j, const json& list, const char* key, const std::optional<double>& max,
                const char* what, const char* unit) {
  if (!max) return;
  if (list.empty()) j.at_most(what, json(), max, unit);
  for (const auto& x : list)
    j.at_most(fmt::format("{} at '{}'", what, x.value("label", "")), figure(x, key), max, unit);
}

json verdict_of(const json& s, const PartLimits& part) {
  const auto& a = *part.acceptance;
  Judge j;
  const auto k = held_scale_factor(s);  // K at 25 C of the temperature model, else the ladder's
  j.range("scale factor", k ? json(k->k_pulse_per_arcsec) : json(), a.sf_pulse_per_arcsec,
          "pulse/arcsec");
  j.range("temperature coefficient",
          s.contains("sf_vs_temp") ? figure(s["sf_vs_temp"], "tc_ppm_per_c") : json(),
          a.sf_tc_ppm_per_c, "ppm/C");
  judge_each(j, s["ladders"], "nonlinearity_max_ppm_fs", a.max_nonlinearity_ppm_fs, "nonlinearity",
             "ppm FS");
  json judged = json::array();  // a drifting plateau's asymmetry without a TC: not judged
  for (const auto& l : s["ladders"]) {
    if (l.value("asymmetry_judged", true) || !a.max_asymmetry_ppm)
      judged.push_back(l);
    else
      j.not_judged.push_back(fmt::format("asymmetry at '{}': {}", l.value("label", ""),
                                         l.value("asymmetry_note", "")));
  }
  if (!judged.empty() || j.not_judged.empty())
    judge_each(j, judged, "asymmetry_ppm", a.max_asymmetry_ppm, "asymmetry", "ppm");
  // A horizontal input axis's "tilt_mrad" is its heading error (acceptance_json.cpp says why):
  // the same limit, named as what it is. A serial's positions share its slot's axis.
  const bool horizontal =
      !s["positions"].empty() && s["positions"][0].value("axis", "") == "horizontal";
  judge_each(j, s["positions"], "tilt_mrad", a.max_tilt_mrad, horizontal ? "heading error" : "tilt",
             "mrad");
  // Every power_cycles step (turn_on_steps when there are two or more, else turn_on).
  if (s.contains("turn_on_steps")) {
    judge_each(j, s["turn_on_steps"], "repeatability_dph", a.max_turn_on_repeatability_dph,
               "turn-on repeatability", "deg/h");
    judge_each(j, s["turn_on_steps"], "max_warmup_s", a.max_warmup_s, "warm-up", "s");
  } else {
    const json turn_on = s.value("turn_on", json());
    j.at_most("turn-on repeatability", figure(turn_on, "repeatability_dph"),
              a.max_turn_on_repeatability_dph, "deg/h");
    j.at_most("warm-up", figure(turn_on, "max_warmup_s"), a.max_warmup_s, "s");
  }
  json v{{"part", part.number},
         {"pass", j.failed.empty()},
         {"checked", j.checked},
         {"failed", j.failed}};
  if (!j.not_judged.empty()) v["not_judged"] = j.not_judged;
  return v;
}

}  // namespace

void judge_acceptance(json& serials, const std::map<std::string, PartLimits>& by_serial) {
  for (auto& s : serials) {
    const auto it = by_serial.find(s.value("serial", ""));
    if (it == by_serial.end() || !it->second.acceptance) continue;
    s["verdict"] = verdict_of(s, it->second);
  }
}

}  // namespace station
