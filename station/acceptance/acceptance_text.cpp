// The end summary's acceptance section.
#include <fmt/format.h>

#include "station/acceptance/acceptance_json.hpp"

namespace station {
namespace {

using nlohmann::json;

/// " (true X)" when the object's "true" has `key` (a simulated gyro), else "".
std::string truth(const json& s, const char* key, const char* format = "{:.4g}") {
  if (!s.contains("true") || !s["true"].is_object() || !s["true"].contains(key) ||
      !s["true"][key].is_number())
    return "";
  return fmt::format(fmt::runtime(std::string(" (true ") + format + ")"),
                     s["true"][key].get<double>());
}

/// The gyro's temperature over the step ("  25.0 C"), or "   - C" when no sample had one.
std::string temp(const json& step) {
  return step.contains("temp_c") ? fmt::format("{:6.1f} C", step["temp_c"].get<double>())
                                 : std::string("     - C");
}

std::string ladder_line(const json& l) {
  std::string out = fmt::format("  scale factor  {:<28} {}  ", l.value("label", ""), temp(l));
  if (!l.value("ok", false))
    return out + "not computed: " + l.value("error", "") +
           fmt::format(" ({} of {} points not measured)\n", l.value("missing", 0),
                       l.value("points", 0));
  out += fmt::format(
      "K {:.7f} +- {:.1e} pulse/arcsec{}, bias {:+.3f} +- {:.3f} deg/h, "
      "nonlinearity {:.1f} ppm FS{} (rms {:.1f})",
      l["sf_pulse_per_arcsec"].get<double>(), l["sf_se_pulse_per_arcsec"].get<double>(),
      truth(l, "sf_pulse_per_arcsec", "{:.7f}"), l["bias_dph"].get<double>(),
      l["bias_se_dph"].get<double>(), l["nonlinearity_max_ppm_fs"].get<double>(),
      truth(l, "nonlinearity_max_ppm_fs", "{:.1f}"), l["nonlinearity_rms_ppm_fs"].get<double>());
  if (l.contains("asymmetry_ppm"))
    out += fmt::format(", asymmetry {:+.1f} +- {:.2g} ppm{}", l["asymmetry_ppm"].get<double>(),
                       l["asymmetry_se_ppm"].get<double>(), truth(l, "asymmetry_ppm", "{:+.1f}"));
  if (!l.value("asymmetry_judged", true))
    out += " (not judged: " + l.value("asymmetry_note", "") + ")";
  if (l.value("drift_corrected", false) && l.value("drift_c", 0.0) > 0)
    out += fmt::format(" [points {:.2g} C apart, brought to {:.2f} C by the run's TC]",
                       l["drift_c"].get<double>(), l["temp_c"].get<double>());
  const int excluded = l.value("points_excluded", 0) + l.value("missing", 0);
  out += fmt::format("; {} of {} points", l.value("points_used", 0), l.value("points", 0));
  if (excluded > 0)
    out += fmt::format(
        " ({} left out: the table did not hold its rate, or a stop, kill or safe "
        "hold cut its window short)",
        excluded);
  return out + "\n";
}

std::string tc_line(const json& s) {
  const json& t = s["sf_vs_temp"];
  if (!t.value("ok", false)) return "  scale factor vs temperature: " + t.value("error", "") + "\n";
  return fmt::format(
      "  scale factor vs temperature: K({:g} C) {:.7f} +- {:.1e} pulse/arcsec{}, "
      "temperature coefficient {:+.3f} +- {:.2g} ppm/C{} over {} plateaus\n",
      t["ref_temp_c"].get<double>(), t["sf_ref_pulse_per_arcsec"].get<double>(),
      t["sf_ref_se_pulse_per_arcsec"].get<double>(), truth(t, "sf_ref_pulse_per_arcsec", "{:.7f}"),
      t["tc_ppm_per_c"].get<double>(), t["tc_se_ppm_per_c"].get<double>(),
      truth(t, "tc_ppm_per_c", "{:+.2f}"), t["plateaus"].get<int>());
}

/// A horizontal axis's figures (acceptance_json.cpp: horizontal_positions_json).
std::string horizontal_figures(const json& s, const json& p) {
  return fmt::format(
      "input axis at heading {:g} deg: heading error {:+.3f} +- {:.3f} mrad{} (clockwise), "
      "bias if level {:+.4f} +- {:.4f} deg/h (the elevation out of the plane is in it: not "
      "measured{}), Earth-rate amplitude {:.5f} +- {:.5f} of W cos(lat)",
      p["nominal_heading_deg"].get<double>(), p["heading_error_mrad"].get<double>(),
      p["heading_error_se_mrad"].get<double>(), truth(s, "heading_error_mrad", "{:+.3f}"),
      p["bias_dph"].get<double>(), p["bias_se_dph"].get<double>(),
      truth(s, "elevation_mrad", "{:+.3f} mrad"), p["amplitude_ratio"].get<double>(),
      p["amplitude_ratio_se"].get<double>());
}

std::string positions_line(const json& s, const json& p) {
  std::string out = fmt::format("  positions     {:<28} {}  ", p.value("label", ""), temp(p));
  if (!p.value("ok", false)) return out + "not computed: " + p.value("error", "") + "\n";
  if (p.value("axis", "") == "horizontal") {
    out += horizontal_figures(s, p);
    if (p.value("excluded", 0) > 0)
      out += fmt::format("; {} angles left out", p["excluded"].get<int>());
    return out + "\n";
  }
  out += fmt::format(
      "input-axis tilt {:.3f} +- {:.3f} mrad{} toward {:.0f} +- {:.0f} deg of the "
      "table, bias {:+.4f} +- {:.4f} deg/h",
      p["tilt_mrad"].get<double>(), p["tilt_se_mrad"].get<double>(),
      truth(s, "misalignment_mrad", "{:.3f}"), p["tilt_direction_table_deg"].get<double>(),
      p["tilt_direction_se_deg"].get<double>(), p["bias_dph"].get<double>(),
      p["bias_se_dph"].get<double>());
  if (!p.value("amplitude_resolved", true)) out += " (tilt not resolved: read as an upper bound)";
  if (p.value("excluded", 0) > 0)
    out += fmt::format("; {} angles left out", p["excluded"].get<int>());
  return out + "\n";
}

/// The simulated turn-on spread, and with the bias windows' own noise (what the sd should show).
std::string sigma_truth(const json& t) {
  if (!t.contains("true") || !t["true"].contains("sigma_with_noise_dph")) return "";
  return fmt::format(" (true {:.4f}; with the windows' noise {:.4f})",
                     t["true"]["sigma_dph"].get<double>(),
                     t["true"]["sigma_with_noise_dph"].get<double>());
}

/// The simulated warm-up under the same band: none when the transient never leaves it.
std::string warmup_truth(const json& t) {
  if (!t.contains("true") || !t["true"].contains("warmup_s")) return "";
  const double w = t["true"]["warmup_s"];
  return w > 0 ? fmt::format(" (true {:.0f} s)", w)
               : std::string(" (true: the simulated transient stays inside the band)");
}

std::string turn_on_line(const json& t, const std::string& head) {
  if (!t.value("ok", false)) return head + "not computed: " + t.value("error", "") + "\n";
  std::string warm = t["max_warmup_s"].is_number()
                         ? fmt::format("longest warm-up {:.0f} s", t["max_warmup_s"].get<double>())
                         : std::string("no turn-on settled");
  return head + fmt::format(
                    "{} turn-ons, repeatability {:.4f} deg/h ({:.0f} % interval {:.4f}..{:.4f}){}, "
                    "mean bias {:+.4f} deg/h; {}{} within +-{:.4f} deg/h of the final value\n",
                    t["turn_ons"].get<int>(), t["repeatability_dph"].get<double>(),
                    100 * t["confidence"].get<double>(), t["repeatability_lower_dph"].get<double>(),
                    t["repeatability_upper_dph"].get<double>(), sigma_truth(t),
                    t["mean_bias_dph"].get<double>(), warm, warmup_truth(t),
                    t["band_dph"].get<double>());
}

std::string verdict_line(const json& v) {
  return fmt::format("  acceptance verdict ({}): {}\n", v.value("part", ""),
                     acceptance_verdict_text(v));
}

}  // namespace

std::string acceptance_verdict_text(const json& v) {
  std::string out = v.value("pass", false) ? fmt::format("PASS, {} limits", v.value("checked", 0))
                                           : std::string("FAIL");
  const char* sep = ": ";
  for (const auto& f : v.value("failed", json::array())) {
    out += sep + f.get<std::string>();
    sep = "; ";
  }
  for (const auto& f : v.value("not_judged", json::array()))
    out += "; not judged: " + f.get<std::string>();
  return out;
}

std::string acceptance_text(const json& serials) {
  if (!serials.is_array() || serials.empty()) return "";
  std::string out =
      "\nacceptance: scale factor (rate ladders), input-axis misalignment "
      "(positions), turn-on repeatability and warm-up (power cycles)\n";
  for (const auto& s : serials) {
    out += s.value("serial", "") + "\n";
    for (const auto& l : s["ladders"]) out += ladder_line(l);
    if (s.contains("sf_vs_temp")) out += tc_line(s);
    for (const auto& p : s["positions"]) out += positions_line(s, p);
    if (s.contains("positions_note"))
      out += "  positions: " + s["positions_note"].get<std::string>() + "\n";
    if (s.contains("turn_on_steps")) {
      for (const auto& t : s["turn_on_steps"])  // the step's number: labels may repeat
        out += turn_on_line(
            t, fmt::format("  turn-on step {:<2} {:<28} {}  ", t.value("step_index", 0) + 1,
                           t.value("label", ""), temp(t)));
    } else if (s.contains("turn_on")) {
      out += turn_on_line(s["turn_on"], "  turn-on: ");
    }
    if (s.contains("verdict")) out += verdict_line(s["verdict"]);
  }
  return out;
}

}  // namespace station
