// The acceptance truth of simulated gyros in the figures' terms.
#include "station/sim/sim_acceptance_truth.hpp"

#include <cmath>

#include "compensation/scale_factor.hpp"
#include "sim_devices/gyro_acceptance.hpp"
#include "station/config/acceptance_steps.hpp"

namespace station {
namespace {

namespace comp = station::compensation;

nlohmann::json serial_truth(const sim::SimGyro& g) {
  const auto& a = g.acceptance;
  nlohmann::json j{{"sf_pulse_per_arcsec", (1.0 + a.sf_error_ppm * 1e-6) / g.pulse_weight_arcsec},
                   {"sf_tc_ppm_per_c", a.sf_tc_ppm_per_c},
                   {"asymmetry_ppm", a.asymmetry_ppm},
                   {"turn_on_sigma_dph", a.turn_on_sigma_dph},
                   {"warmup_tau_s", a.warmup_tau_s},
                   {"warmup_amplitude_dph", a.warmup_amplitude_dph}};
  if (a.input_axis == sim::InputAxis::horizontal) {
    // The positions' figures of a horizontal axis (acceptance_run.hpp, heading_error_rad): the
    // heading error clockwise, and the elevation out of the table's plane the run cannot see.
    j["nominal_heading_deg"] = a.nominal_heading_deg;
    j["heading_error_mrad"] = sim::heading_error_rad(a) * 1e3;
    j["elevation_mrad"] = a.misalignment_rad * 1e3;
  } else {
    j["misalignment_mrad"] = a.misalignment_rad * 1e3;
  }
  return j;
}

/// The ladder's figures on the gyro's noise-free output: pulses/s = (3600 w_in (1 + e(w, dT))
/// + Earth) / pulse weight, w_in the table rate along the input axis (gyro_acceptance.hpp).
/// A nonlinear response's least-squares line depends on the points, so the truth is fitted over
/// the points the station used (`used`: the ladder's used_points); without them, over the
/// schedule. The line has equal weights (scale_factor.hpp): the errors given are only checked.
nlohmann::json ladder_truth(const sim::SimGyro& g, const Step& step, double temp_c,
                            double earth_dph, const nlohmann::json& used) {
  std::vector<comp::LadderPoint> points;
  const double dt_c = temp_c - g.truth.ref_temp_c, c = sim::table_coupling(g.acceptance);
  const auto add = [&](double table_dps) {
    const double in_dps = table_dps * c;
    const double e = 1e-6 * sim::scale_factor_error_ppm(g.acceptance, in_dps, dt_c);
    const double out = (3600.0 * in_dps * (1.0 + e) + earth_dph) / g.pulse_weight_arcsec;
    points.push_back({table_dps, earth_dph, out, 1.0, true});
  };
  if (used.is_array() && !used.empty()) {
    for (const auto& p : used)  // input_rate_dps = table + Earth / 3600 (scale_factor.hpp)
      add(p.value("input_rate_dps", 0.0) - earth_dph / 3600.0);
  } else {
    for (const auto& p : acceptance_schedule(step)) add(p.demand);
  }
  const auto fit = comp::analyze_rate_ladder(points);
  if (!fit) return nullptr;
  nlohmann::json j{{"sf_pulse_per_arcsec", fit->sf_pulse_per_arcsec},
                   {"nonlinearity_max_ppm_fs", fit->nonlinearity_max_ppm_fs}};
  if (fit->asymmetry) j["asymmetry_ppm"] = fit->asymmetry->asymmetry_ppm;
  return j;
}

/// A power_cycles step's truth under its own band.
void add_turn_on_truth(nlohmann::json& t, const sim::SimGyro& g) {
  if (t.value("band_dph", 0.0) <= 0) return;
  // The warm-up time the band gives a noise-free transient A exp(-t/tau): tau ln(|A|/band).
  const double a = std::abs(g.acceptance.warmup_amplitude_dph);
  const double band = t["band_dph"];
  // The sd of the turn-on biases holds each one's estimation noise (its window's SE) beside
  // the turn-on spread: what the figure should show is their root sum of squares.
  const double se = t.value("mean_bias_se_dph", 0.0);
  t["true"] = {{"sigma_dph", g.acceptance.turn_on_sigma_dph},
               {"sigma_with_noise_dph", std::hypot(g.acceptance.turn_on_sigma_dph, se)},
               {"warmup_s", a > band ? g.acceptance.warmup_tau_s * std::log(a / band) : 0.0}};
}

}  // namespace

nlohmann::json with_acceptance_truth(nlohmann::json serials, const sim::SimWorld& world,
                                     const Protocol& protocol) {
  for (auto& s : serials) {
    for (const auto& g : world.gyros()) {
      if (g.serial != s.value("serial", "")) continue;
      s["true"] = serial_truth(g);
      std::vector<comp::PlateauScaleFactor> plateaus;
      for (auto& l : s["ladders"]) {
        const int i = l.value("step_index", -1);
        if (i < 0 || i >= static_cast<int>(protocol.steps.size())) continue;
        l["true"] = ladder_truth(
            g, protocol.steps[static_cast<std::size_t>(i)], l.value("temp_c", g.truth.ref_temp_c),
            s.value("earth_rate_dph", 0.0), l.value("used_points", nlohmann::json()));
        if (l["true"].is_object())
          plateaus.push_back({l.value("temp_c", 0.0), l["true"]["sf_pulse_per_arcsec"], 1.0});
      }
      if (s.contains("sf_vs_temp") && s["sf_vs_temp"].contains("ref_temp_c")) {
        const auto fit =
            comp::fit_scale_factor_vs_temperature(plateaus, s["sf_vs_temp"]["ref_temp_c"]);
        if (fit)
          s["sf_vs_temp"]["true"] = {{"sf_ref_pulse_per_arcsec", fit->sf_ref_pulse_per_arcsec},
                                     {"tc_ppm_per_c", fit->tc_ppm_per_c}};
      }
      if (s.contains("turn_on")) add_turn_on_truth(s["turn_on"], g);
      if (s.contains("turn_on_steps"))
        for (auto& t : s["turn_on_steps"]) add_turn_on_truth(t, g);
    }
  }
  return serials;
}

}  // namespace station
