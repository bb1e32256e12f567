// Acceptance figures as JSON.
#include "station/acceptance/acceptance_json.hpp"

#include <cmath>

namespace station {
namespace {

using nlohmann::json;
namespace comp = station::compensation;

template <class T>
json not_computed(const comp::Computed<T>& c) {
  return {{"ok", false}, {"error", c.error()}};
}

/// A step's head (step_index, label, points, temp_c) with its own `counts`, and {"ok": false,
/// "error"} when its fit was not computed.
template <class Figures>
json step_json(const Figures& f, const json& counts) {
  json j{{"step_index", f.step_index}, {"label", f.label}, {"points", f.points}};
  j.update(counts);
  if (std::isfinite(f.temp_c)) j["temp_c"] = f.temp_c;
  if (!f.fit) j.update(not_computed(f.fit));
  return j;
}

json ladder_json(const LadderFigures& l) {
  json j = step_json(l, {{"missing", l.missing}});
  if (!l.fit) return j;
  const auto& f = *l.fit;
  j.update({{"ok", true},
            {"sf_pulse_per_arcsec", f.sf_pulse_per_arcsec},
            {"sf_se_pulse_per_arcsec", f.sf_se_pulse_per_arcsec},
            {"bias_dph", f.bias_dph},
            {"bias_se_dph", f.bias_se_dph},
            {"nonlinearity_max_ppm_fs", f.nonlinearity_max_ppm_fs},
            {"nonlinearity_rms_ppm_fs", f.nonlinearity_rms_ppm_fs},
            {"full_scale_dps", f.full_scale_dps},
            {"points_used", f.points_used},
            {"points_excluded", f.points_excluded}});
  // Each used point: its input, its residual and its standard error (a reader can redo the
  // line over the same points, as the simulator's truth does: sim_acceptance_truth.cpp).
  auto& used = j["used_points"] = json::array();
  for (const auto& r : f.residuals)
    used.push_back({{"input_rate_dps", r.input_rate_dps},
                    {"residual_ppm_fs", r.residual_ppm_fs},
                    {"output_se_pps", r.output_se_pps}});
  // The points' temperature spread, and whether the run's TC brought them to temp_c
  // (scale_factor.hpp, "A drifting plateau").
  if (std::isfinite(f.temp_c)) j["drift_c"] = f.drift_c;
  j["drift_corrected"] = f.drift_corrected;
  if (f.asymmetry) {
    j["asymmetry_ppm"] = f.asymmetry->asymmetry_ppm;
    j["asymmetry_se_ppm"] = f.asymmetry->asymmetry_se_ppm;
    j["asymmetry_judged"] = f.asymmetry->judged;
    if (!f.asymmetry->judged) j["asymmetry_note"] = f.asymmetry_note;
  } else {
    j["asymmetry_note"] = f.asymmetry_note;
  }
  return j;
}

/// A horizontal input axis's positions. "tilt_mrad" (what a part's max_tilt_mrad judges, the
/// store keeps and history charts) is its heading error: of the input-axis misalignment (IEEE Std
/// 647-2006 and 952-1997 test items; IEEE Std 528's terms: the angle between the input axis and
/// its input reference axis, here the slot's axis) the part the Earth rate's projection shows,
/// the one in the table's plane. The elevation out of that plane adds W sin(lat) sin(e) to the
/// constant, which holds the bias as well: no figure without a known bias (positions.hpp), so
/// not judged, and "bias_dph" is the bias if the axis is level.
json horizontal_positions_json(const PositionFigures& p) {
  json j{{"step_index", p.step_index}, {"label", p.label},
         {"points", p.points},         {"excluded", p.excluded},
         {"axis", "horizontal"},       {"nominal_heading_deg", *p.nominal_heading_deg}};
  if (std::isfinite(p.temp_c)) j["temp_c"] = p.temp_c;
  if (!p.horizontal) {
    j.update(not_computed(p.horizontal));
    return j;
  }
  const auto& h = *p.horizontal;
  const double err_mrad = heading_error_rad(h) * 1e3,
               se_mrad = h.in_plane_misalignment_se_rad * 1e3;
  j.update({{"ok", true},
            {"heading_error_mrad", err_mrad},
            {"heading_error_se_mrad", se_mrad},
            {"tilt_mrad", err_mrad},
            {"tilt_se_mrad", se_mrad},
            {"bias_dph", h.bias_if_level_dph},
            {"bias_se_dph", h.bias_if_level_se_dph},
            {"bias_note", "the bias if the axis is level: its elevation's Earth rate is in it"},
            {"elevation_note",
             "the axis's elevation out of the table's plane and the bias are one constant on a "
             "table turning about up; not measured"},
            {"amplitude_ratio", h.amplitude_ratio},
            {"amplitude_ratio_se", h.amplitude_ratio_se},
            {"amplitude_resolved", h.fit.amplitude_resolved}});
  return j;
}

json positions_json(const PositionFigures& p) {
  if (p.nominal_heading_deg) return horizontal_positions_json(p);
  json j = step_json(p, {{"excluded", p.excluded}});
  if (!p.fit) return j;
  const auto& f = *p.fit;
  j.update({{"ok", true},
            {"tilt_mrad", f.tilt_rad * 1e3},
            {"tilt_se_mrad", f.tilt_se_rad * 1e3},
            {"tilt_direction_table_deg", f.tilt_direction_table_deg},
            {"tilt_direction_se_deg", f.tilt_direction_se_deg},
            {"bias_dph", f.bias_dph},
            {"bias_se_dph", f.bias_se_dph},
            {"amplitude_resolved", f.fit.amplitude_resolved}});
  return j;
}

json turn_on_json(const comp::Computed<comp::TurnOnResult>& t, double band_dph) {
  if (!t) return not_computed(t);
  const auto& r = t->repeatability;
  json biases = json::array(), warmups = json::array();
  for (const auto& f : t->turn_ons) {
    biases.push_back(f.bias_dph);
    warmups.push_back(f.warmup_s ? json(*f.warmup_s) : json(nullptr));
  }
  return {{"ok", true},
          {"turn_ons", r.turn_ons},
          {"repeatability_dph", r.repeatability_dph},
          {"repeatability_lower_dph", r.repeatability_lower_dph},
          {"repeatability_upper_dph", r.repeatability_upper_dph},
          {"confidence", r.confidence},
          {"mean_bias_dph", r.mean_bias_dph},
          {"mean_bias_se_dph", t->mean_bias_se_dph},
          {"max_warmup_s", t->max_warmup_s ? json(*t->max_warmup_s) : json(nullptr)},
          {"not_settled", t->not_settled},
          {"band_dph", band_dph},
          {"biases_dph", biases},
          {"warmups_s", warmups}};
}

json sf_vs_temp_json(const comp::Computed<comp::ScaleFactorTemperatureFit>& t) {
  if (!t) return not_computed(t);
  return {{"ok", true},
          {"ref_temp_c", t->ref_temp_c},
          {"sf_ref_pulse_per_arcsec", t->sf_ref_pulse_per_arcsec},
          {"sf_ref_se_pulse_per_arcsec", t->sf_ref_se_pulse_per_arcsec},
          {"tc_ppm_per_c", t->tc_ppm_per_c},
          {"tc_se_ppm_per_c", t->tc_se_ppm_per_c},
          {"plateaus", t->plateaus}};
}

}  // namespace

json acceptance_json(const std::vector<SerialAcceptance>& serials) {
  json out = json::array();
  for (const auto& s : serials) {
    json j{{"serial", s.serial},
           {"earth_rate_dph", s.earth_rate_dph},
           {"ladders", json::array()},
           {"positions", json::array()}};
    for (const auto& l : s.ladders) j["ladders"].push_back(ladder_json(l));
    for (const auto& p : s.positions) j["positions"].push_back(positions_json(p));
    if (s.sf_vs_temp) j["sf_vs_temp"] = sf_vs_temp_json(*s.sf_vs_temp);
    if (s.turn_on) j["turn_on"] = turn_on_json(*s.turn_on, s.turn_on_band_dph);
    // Two or more power_cycles steps: each one's figures ("turn_on" is the first's).
    if (s.turn_on_steps.size() > 1) {
      auto& steps = j["turn_on_steps"] = json::array();
      for (const auto& t : s.turn_on_steps) {
        json one = turn_on_json(t.result, t.band_dph);
        one.update({{"step_index", t.step_index}, {"label", t.label}});
        if (std::isfinite(t.temp_c)) one["temp_c"] = t.temp_c;
        steps.push_back(std::move(one));
      }
    }
    if (!s.positions_note.empty()) j["positions_note"] = s.positions_note;
    out.push_back(std::move(j));
  }
  return out;
}

}  // namespace station
