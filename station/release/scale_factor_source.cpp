// The scale-factor model of a coefficient block, from the acceptance figures of the serial's runs.
#include "station/release/scale_factor_source.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "station/acceptance/acceptance_json.hpp"
#include "station/acceptance/acceptance_run.hpp"
#include "station/store/acceptance_results.hpp"

namespace station {
namespace {

namespace comp = station::compensation;

/// w and E of the serial's slot in every run of the fit; empty (with why) when they differ.
std::optional<std::pair<double, double>> fit_slot_scale(Store& store, const FitRecord& fit,
                                                        std::string& why) {
  std::optional<std::pair<double, double>> we;
  for (const auto run : fit.runs)
    for (const auto& s : store.run_slots(run)) {
      if (s.serial != fit.serial) continue;
      const std::pair<double, double> here{s.pulse_weight_arcsec, s.earth_rate_dph};
      if (we && *we != here) {
        why = fmt::format(
            "the fit's runs differ in pulse weight or Earth rate along the axis ({} vs {} "
            "arcsec, {} vs {} deg/h): its bias model cannot be put in input units",
            we->first, here.first, we->second, here.second);
        return std::nullopt;
      }
      we = here;
    }
  if (!we) why = "the fit's runs hold no slot of the serial";
  return we;
}

/// The span of plateau temperatures: the ladders that gave a scale factor.
void set_ladder_span(const SerialAcceptance& a, ScaleFactorModel& m) {
  m.t_min_c = HUGE_VAL;
  m.t_max_c = -HUGE_VAL;
  for (const auto& l : a.ladders)
    if (l.fit && std::isfinite(l.temp_c)) {
      m.t_min_c = std::min(m.t_min_c, l.temp_c);
      m.t_max_c = std::max(m.t_max_c, l.temp_c);
      ++m.plateaus;
    }
}

/// The model of one serial's figures of run `run`. K0 is the K the serial is held to
/// (held_scale_factor, the verdict's and history's rule): K at T_ref of the fit across its
/// plateaus, with its TC; else its one ladder's K at that ladder's temperature, TC 0 (noted).
std::optional<ScaleFactorModel> model_of(const SerialAcceptance& a, std::int64_t run,
                                         double t_ref_c, std::string& note) {
  const auto held = held_scale_factor(acceptance_json({a}).at(0));
  if (!held) return std::nullopt;
  ScaleFactorModel m;
  m.k0_pulse_per_arcsec = held->k_pulse_per_arcsec;
  m.k0_se_pulse_per_arcsec = held->se_pulse_per_arcsec;
  m.runs = {run};
  set_ladder_span(a, m);
  if (a.sf_vs_temp && a.sf_vs_temp->ok()) {
    const comp::ScaleFactorTemperatureFit& t = a.sf_vs_temp->value();
    m.tc_ppm_per_c = t.tc_ppm_per_c;
    m.tc_se_ppm_per_c = t.tc_se_ppm_per_c;
    m.t_ref_c = t.ref_temp_c;
    note = fmt::format("from the rate ladders of run {} ({} plateaus)", run, m.plateaus);
    return m;
  }
  // One ladder (or plateaus too close for a temperature model: the one nearest 25 C): K holds
  // at its temperature (or, when it had none, K is all there is).
  m.t_ref_c = held->temp_c.value_or(t_ref_c);
  m.t_min_c = m.t_max_c = m.t_ref_c;
  m.plateaus = 1;
  note = fmt::format(
      "from one rate ladder of run {}: no temperature coefficient measured, taken as 0", run);
  return m;
}

/// The model run `run` gives the serial, if any.
std::optional<ScaleFactorModel> model_of_run(Store& store, std::int64_t run, const FitRecord& fit,
                                             std::string& note) {
  // Only a protocol with a ladder can give one: the others are not analysed at all.
  const auto rec = store.find_run(run);
  if (!rec || rec->protocol_text.find("rate_ladder") == std::string::npos) return std::nullopt;
  for (const auto& a : run_acceptance(store, run, fit.fit.spec.ref_temp_c))
    if (a.serial == fit.serial) return model_of(a, run, fit.fit.spec.ref_temp_c, note);
  return std::nullopt;
}

}  // namespace

ScaleFactorSource find_scale_factor(Store& store, const FitRecord& fit) {
  std::vector<std::int64_t> order(fit.runs);
  std::sort(order.rbegin(), order.rend());
  auto others = store.runs_of_serial(fit.serial);
  std::sort(others.rbegin(), others.rend());
  for (const auto r : others)
    if (std::find(order.begin(), order.end(), r) == order.end()) order.push_back(r);
  ScaleFactorSource out;
  for (const auto run : order) {
    out.model = model_of_run(store, run, fit, out.note);
    if (out.model) break;
  }
  if (!out.model) {
    out.note = "not measured (no rate ladder of this serial gave a scale factor)";
    return out;
  }
  std::string why;
  const auto we = fit_slot_scale(store, fit, why);
  if (!we) return {std::nullopt, "not attached: " + why};
  out.model->pulse_weight_arcsec = we->first;
  out.model->earth_rate_dph = we->second;
  return out;
}

std::string scale_factor_text(const ScaleFactorSource& s) {
  if (!s.model) return "scale factor: " + s.note;
  const ScaleFactorModel& m = *s.model;
  return fmt::format(
      "scale factor: K0 {:.9g} +- {:.2g} pulse/arcsec at {:.2f} C, {} over {:.2f}..{:.2f} C; {}",
      m.k0_pulse_per_arcsec, m.k0_se_pulse_per_arcsec, m.t_ref_c,
      m.tc_se_ppm_per_c
          ? fmt::format("TC {:+.3f} +- {:.2g} ppm/C", m.tc_ppm_per_c, *m.tc_se_ppm_per_c)
          : std::string("TC not measured (0)"),
      m.t_min_c, m.t_max_c, s.note);
}

}  // namespace station
