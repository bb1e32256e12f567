// The acceptance pages' figures as data (report_acceptance.hpp): pure functions of the figures
// station/acceptance computed and the series report_acceptance_load read.
#include "station/report/report_acceptance.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace station::report {

namespace sc = station::compensation;
namespace {

constexpr double kPpm = 1e6;

/// "scale factor, room (step 3, 25.0 °C)": a step's series label, unique within its figure.
std::string step_label(const std::string& label, int step_index, double temp_c) {
  return std::isfinite(temp_c)
             ? fmt::format("{} (step {}, {:.1f} \u00b0C)", label, step_index + 1, temp_c)
             : fmt::format("{} (step {})", label, step_index + 1);
}

/// "; "-joined reasons, each "label: why".
std::string joined(const std::vector<std::string>& why) {
  std::string out;
  for (const auto& w : why) out += (out.empty() ? "" : "; ") + w;
  return out;
}

/// The ladders that enter the temperature fit (acceptance_run: computed, at a finite temperature).
std::vector<const LadderFigures*> fitted_ladders(const std::vector<LadderFigures>& ladders) {
  std::vector<const LadderFigures*> out;
  for (const auto& l : ladders)
    if (l.fit && std::isfinite(l.temp_c)) out.push_back(&l);
  return out;
}

}  // namespace

Figure ladder_residuals_figure(std::string id, const SerialAcceptance& a) {
  Figure f = make_figure(
      std::move(id),
      "Ladder residuals from the least-squares line against the input rate, " + a.serial,
      "input rate (\u00b0/s)", "residual (ppm of full scale)");
  std::vector<std::string> why;
  for (const auto& l : a.ladders) {
    if (!l.fit) {
      why.push_back(step_label(l.label, l.step_index, l.temp_c) + ": " + l.fit.error());
      continue;
    }
    Series s;
    s.label = step_label(l.label, l.step_index, l.temp_c);
    // Each point's error in the residual's unit: se / (|K| FS), FS in arcsec/s (scale_factor.hpp).
    const double fs_pps = std::abs(l.fit->sf_pulse_per_arcsec) * l.fit->full_scale_dps * 3600.0;
    for (const auto& r : l.fit->residuals) {
      const double se_ppm = fs_pps > 0 ? r.output_se_pps / fs_pps * 1e6 : 0.0;
      s.x.push_back(r.input_rate_dps);
      s.y.push_back(r.residual_ppm_fs);
      s.y_low.push_back(r.residual_ppm_fs - se_ppm);
      s.y_high.push_back(r.residual_ppm_fs + se_ppm);
    }
    s.whiskers = true;
    f.series.push_back(std::move(s));
  }
  f.note = why.empty() ? "" : "Not computed: " + joined(why) + ".";
  return f;
}

double sf_line_se(const std::vector<LadderFigures>& ladders,
                  const sc::ScaleFactorTemperatureFit& fit, double temp_c) {
  // (X'WX) of the design [1, T_i - T_ref] with weights 1/SE(K_i)^2, inverted in closed form.
  double s0 = 0, s1 = 0, s2 = 0;
  for (const auto* l : fitted_ladders(ladders)) {
    const double w = 1.0 / (l->fit->sf_se_pulse_per_arcsec * l->fit->sf_se_pulse_per_arcsec);
    const double d = l->temp_c - fit.ref_temp_c;
    s0 += w;
    s1 += w * d;
    s2 += w * d * d;
  }
  const double det = s0 * s2 - s1 * s1, d = temp_c - fit.ref_temp_c;
  if (!(det > 0)) return std::nan("");
  return fit.se_scale * std::sqrt((s2 - 2 * s1 * d + s0 * d * d) / det);
}

Figure sf_temperature_figure(std::string id, const SerialAcceptance& a) {
  Figure f = make_figure(std::move(id),
                         "Scale factor against gyro temperature with the fitted line, " + a.serial,
                         "gyro temperature (\u00b0C)", "K \u2212 K(T_ref) (ppm of K(T_ref))");
  if (!a.sf_vs_temp || !*a.sf_vs_temp) {
    f.note = a.sf_vs_temp ? "Not computed: " + a.sf_vs_temp->error()
                          : fmt::format(
                                "Not computed: {} ladder(s) computed at a temperature; the "
                                "temperature fit needs plateaus at two temperatures.",
                                fitted_ladders(a.ladders).size());
    return f;
  }
  const auto& t = a.sf_vs_temp->value();
  const double k0 = t.sf_ref_pulse_per_arcsec;
  Series points;
  points.label = "scale factor per plateau (\u00b11\u03c3)";
  points.whiskers = true;
  double lo = t.ref_temp_c, hi = t.ref_temp_c;
  for (const auto* l : fitted_ladders(a.ladders)) {
    const double y = (l->fit->sf_pulse_per_arcsec - k0) / k0 * kPpm;
    const double se = l->fit->sf_se_pulse_per_arcsec / k0 * kPpm;
    points.x.push_back(l->temp_c);
    points.y.push_back(y);
    points.y_low.push_back(y - se);
    points.y_high.push_back(y + se);
    lo = std::min(lo, l->temp_c);
    hi = std::max(hi, l->temp_c);
  }
  Series line;
  line.label = fmt::format(
      "K0 + s\u00b7(T \u2212 {:g} \u00b0C), TC {:.3g} \u00b1 {:.2g} ppm/\u00b0C "
      "(\u00b11\u03c3 band)",
      t.ref_temp_c, t.tc_ppm_per_c, t.tc_se_ppm_per_c);
  line.line = true;
  constexpr int kSteps = 20;
  for (int i = 0; i <= kSteps; ++i) {
    const double temp = lo + (hi - lo) * i / kSteps;
    const double y = t.tc_ppm_per_c * (temp - t.ref_temp_c);
    const double se = sf_line_se(a.ladders, t, temp) / k0 * kPpm;
    line.x.push_back(temp);
    line.y.push_back(y);
    line.y_low.push_back(y - se);
    line.y_high.push_back(y + se);
  }
  f.series = {points, line};
  return f;
}

std::string turn_on_step_title(const TurnOnStep& s) {
  if (s.step_index < 0) return "";  // a serial's figures built without their steps
  return step_label(s.label.empty() ? std::string("power cycles") : s.label, s.step_index,
                    s.temp_c);
}

std::vector<TurnOnStep> turn_on_steps_of(const SerialAcceptanceReport& a) {
  const auto& f = a.figures;
  if (!f.turn_on_steps.empty()) return f.turn_on_steps;
  TurnOnStep one;
  one.step_index = -1;
  one.temp_c = std::nan("");
  one.result =
      f.turn_on ? *f.turn_on : sc::Computed<sc::TurnOnResult>(sc::NotComputed{"no power cycles"});
  one.curves = a.warmups;
  one.band_dph = f.turn_on_band_dph;
  return {one};
}

namespace {

/// "SN1" or "SN1, hot (step 9, 70.0 °C)": whose figure, and which step's.
std::string whose(const std::string& serial, const TurnOnStep& step) {
  const std::string t = turn_on_step_title(step);
  return t.empty() ? serial : serial + ", " + t;
}

TurnOnStep first_step(const SerialAcceptanceReport& a) {
  return turn_on_steps_of(a).front();
}

}  // namespace

Figure turn_on_figure(std::string id, const SerialAcceptance& a) {
  return turn_on_figure(std::move(id), a.serial, first_step({a, {}, {}}));
}

Figure turn_on_figure(std::string id, const std::string& serial, const TurnOnStep& step) {
  Figure f = make_figure(
      std::move(id),
      "Turn-on biases with the turn-on-to-turn-on repeatability, " + whose(serial, step),
      "turn-on (number)", "bias (\u00b0/h)");
  if (!step.result) {
    f.note = "Not computed: " + step.result.error();
    return f;
  }
  const auto& r = step.result.value();
  Series b, band;
  b.label = "turn-on bias (\u00b11\u03c3)";
  b.whiskers = true;
  const auto& rep = r.repeatability;
  band.label = fmt::format("mean \u00b1 \u03c3 (\u03c3 {:.3g} \u00b0/h)", rep.repeatability_dph);
  band.line = true;
  for (std::size_t k = 0; k < r.turn_ons.size(); ++k) {
    const auto& t = r.turn_ons[k];
    const double x = static_cast<double>(k + 1);
    b.x.push_back(x);
    b.y.push_back(t.bias_dph);
    b.y_low.push_back(t.bias_dph - t.bias_se_dph);
    b.y_high.push_back(t.bias_dph + t.bias_se_dph);
    band.x.push_back(x);
    band.y.push_back(rep.mean_bias_dph);
    band.y_low.push_back(rep.mean_bias_dph - rep.repeatability_dph);
    band.y_high.push_back(rep.mean_bias_dph + rep.repeatability_dph);
  }
  f.series = {b, band};
  return f;
}

Figure warmup_figure(std::string id, const SerialAcceptanceReport& a) {
  return warmup_figure(std::move(id), a.figures.serial, first_step(a));
}

Figure warmup_figure(std::string id, const std::string& serial, const TurnOnStep& step) {
  Figure f = make_figure(
      std::move(id),
      "Warm-up: bias minus its final value against the time since power-up, " + whose(serial, step),
      "time since power-up (s)", "bias \u2212 final value (\u00b0/h)");
  if (!step.result) {
    f.note = "Not computed: " + step.result.error();
    return f;
  }
  const auto& r = step.result.value();
  const auto& warmups = step.curves;
  const double band_dph = step.band_dph;
  if (warmups.size() != r.turn_ons.size()) {
    f.note = fmt::format("Not drawn: {} turn-ons analysed, {} read from the samples.",
                         r.turn_ons.size(), warmups.size());
    return f;
  }
  double t_hi = -INFINITY;
  for (std::size_t k = 0; k < r.turn_ons.size(); ++k) {
    const auto& c = warmups[k];
    const auto& t = r.turn_ons[k];
    // The curve is what the analysis judged: it gives the analysis' own warm-up time.
    const auto again = sc::warmup_time_s({c.t_s, c.bias_dph}, t.final_dph, band_dph);
    if (!again || again->has_value() != t.warmup_s.has_value() ||
        (t.warmup_s && std::abs(**again - *t.warmup_s) > 1e-6)) {
      f.series.clear();
      f.note = fmt::format(
          "Not drawn: turn-on {}'s bins read from the samples do not give the "
          "analysis' warm-up time.",
          k + 1);
      return f;
    }
    Series s;
    s.label = fmt::format("turn-on {} (warm-up {})", k + 1,
                          t.warmup_s ? fmt::format("{:.0f} s", *t.warmup_s) : "not settled");
    s.line = true;
    s.x = c.t_s;
    for (const double b : c.bias_dph) s.y.push_back(b - t.final_dph);
    if (!c.t_s.empty()) t_hi = std::max(t_hi, c.t_s.back());
    f.series.push_back(std::move(s));
  }
  if (std::isfinite(t_hi)) {
    Series band;
    band.label = fmt::format("final value \u00b1 band ({:.3g} \u00b0/h)", band_dph);
    band.line = true;
    // From power-up to the end of the last bin: the whole powered time.
    band.x = {0.0, t_hi + kTurnOnBinS / 2};
    band.y = {0.0, 0.0};
    band.y_low = {-band_dph, -band_dph};
    band.y_high = {band_dph, band_dph};
    f.series.push_back(std::move(band));
  }
  return f;
}

Figure positions_figure(std::string id, const SerialAcceptanceReport& a) {
  const auto& acc = a.figures;
  Figure f = make_figure(std::move(id),
                         "Earth rate along the input axis (output minus the fitted bias) against "
                         "the table angle, " +
                             acc.serial,
                         "table angle (\u00b0)", "Earth-rate projection (\u00b0/h)");
  std::vector<std::string> why, notes;
  if (!acc.positions_note.empty()) why.push_back(acc.positions_note);
  for (std::size_t i = 0; i < acc.positions.size(); ++i) {
    const auto& p = acc.positions[i];
    const std::string name = step_label(p.label, p.step_index, p.temp_c);
    std::string not_computed;
    const auto* projection = positions_projection(p, &not_computed);
    if (projection == nullptr) {
      why.push_back(name + ": " + not_computed);
      continue;
    }
    const auto& v = *projection;
    const auto& angles =
        i < a.position_angles_deg.size() ? a.position_angles_deg[i] : std::vector<double>{};
    if (angles.size() != v.residuals_dph.size()) {
      why.push_back(name + ": its angles could not be matched to the fit's positions");
      continue;
    }
    // y = c + A cos(theta - theta0) (positions.hpp), less the bias: the projection alone.
    const double offset = v.constant_dph - positions_bias_dph(p);
    const auto model = [&](double deg) {
      return offset + v.amplitude_dph * std::cos((deg - v.phase_deg) * std::numbers::pi / 180.0);
    };
    Series pts, curve;
    pts.label = name;
    pts.large_points = true;
    for (std::size_t k = 0; k < angles.size(); ++k) {
      pts.x.push_back(angles[k]);
      pts.y.push_back(model(angles[k]) + v.residuals_dph[k]);
    }
    curve.label = fmt::format("fitted sinusoid, step {}", p.step_index + 1);
    curve.line = true;
    for (int deg = 0; deg <= 360; deg += 5) {
      curve.x.push_back(deg);
      curve.y.push_back(model(deg));
    }
    if (!v.amplitude_resolved)
      notes.push_back(name + (p.nominal_heading_deg
                                  ? ": amplitude below 3 SE, the heading error is not resolved"
                                  : ": amplitude below 3 SE, the tilt is an upper bound"));
    f.series.push_back(std::move(curve));  // under its points
    f.series.push_back(std::move(pts));
  }
  if (!why.empty()) notes.insert(notes.begin(), "Not computed: " + joined(why));
  f.note = notes.empty() ? "" : joined(notes) + ".";
  return f;
}

}  // namespace station::report
