// A run's acceptance figures from its acceptance_point events and its samples.
#include "station/acceptance/acceptance_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "compensation/earth_rate.hpp"
#include "station/config/acceptance_steps.hpp"
#include "station/config/protocol.hpp"

namespace station {
namespace {

namespace comp = station::compensation;

/// One acceptance_point event as stored.
struct PointEvent {
  int point = 0;
  double measure_s = 0, end_s = 0;
  std::optional<double> table_mean;
  bool held = false;
};
using StepPoints = std::map<int, std::map<int, PointEvent>>;  // step -> point -> event

StepPoints point_events(Store& store, std::int64_t run_id) {
  StepPoints out;
  for (const auto& e : store.event_rows(run_id)) {
    if (e.kind != "acceptance_point" || !e.data_json) continue;
    const auto j = nlohmann::json::parse(*e.data_json, nullptr, false);
    if (!j.is_object() || !j.contains("step_index") || !j.contains("point")) continue;
    PointEvent p;
    p.point = j.value("point", 0);
    p.measure_s = j.value("measure_s", 0.0);
    p.end_s = j.value("end_s", 0.0);
    if (j.contains("table_mean") && j["table_mean"].is_number()) p.table_mean = j["table_mean"];
    p.held = j.value("held", false);
    out[j.value("step_index", -1)][p.point] = p;  // a resumed run's later event wins
  }
  return out;
}

/// Mean and standard error of the mean of `v`; se empty below two values.
struct MeanSe {
  double mean = 0;
  std::optional<double> se;
  std::size_t n = 0;
};
MeanSe mean_se(const std::vector<double>& v) {
  MeanSe m;
  m.n = v.size();
  if (v.empty()) return m;
  for (double x : v) m.mean += x;
  m.mean /= static_cast<double>(v.size());
  if (v.size() < 2) return m;
  double ss = 0;
  for (double x : v) ss += (x - m.mean) * (x - m.mean);
  m.se = std::sqrt(ss / static_cast<double>(v.size() - 1) / static_cast<double>(v.size()));
  return m;
}

/// The least error of a mean count rate over `window_s`, in pulses/s: the count is exact to the
/// phase of the first and last pulse, two uniform errors of one pulse, sd 1/sqrt(6) pulse (GUM
/// 4.3.7, the rectangular distribution, for their difference's triangle). Times the pulse weight
/// (arcsec) it is deg/h (arcsec/s = deg/h).
double mean_quantization_pps(double window_s) {
  return window_s > 0 ? 1.0 / (window_s * std::sqrt(6.0)) : 0.0;
}

/// The samples of [from_s, to_s) with a rate: pulses per second, rate deg/h and sensor A.
struct Window {
  std::vector<double> pps, rate_dph, temp_c;
  double span_s = 0;  ///< the time the samples cover (their intervals), s
  /// The least error of a mean over the window, pulses/s (mean_quantization_pps).
  double quantization_pps() const { return mean_quantization_pps(span_s); }
};

/// The mean of a window's series and its standard error by batch means (Schmeiser, "Batch size
/// effects in the analysis of simulation output", Oper. Res. 30(3):556, 1982): the series in
/// up to kBatches consecutive batches of equal count, the error from the spread of the batch
/// means. Not sd/sqrt(n) of the 1 Hz values: their pulse quantization (one pulse is 1.5 deg/h in
/// a second) is anticorrelated from second to second. The batch means still carry it: batch b's
/// count is exact to the phases e_b, e_(b+1) of its first and last pulse, so its mean errs by
/// (e_(b+1) - e_b) / D (D its span), variance 2 var(e) / D^2 with var(e) = 1/12 pulse^2 (GUM
/// 4.3.7, rectangular), while the whole window's mean errs only by (e_k - e_0) / T, the sum
/// telescoping. With `floor` = that least error of the window's mean (sd sqrt(2/12)/T) and k
/// batches (D = T/k), a batch mean's quantization variance is k^2 floor^2; the rest of the
/// spread (the gyro's own noise, correlated or not within a batch) is s_b^2 - k^2 floor^2
/// (clipped at 0), which the window's mean carries divided by k. So SE^2 = max(s_b^2 - k^2
/// floor^2, 0) / k + floor^2 (tests/station/test_acceptance_coverage.cpp checks the errors end
/// to end).
MeanSe batch_mean_se(const std::vector<double>& v, double floor) {
  constexpr std::size_t kBatches = 10, kMinPerBatch = 5;
  const std::size_t k = std::min(kBatches, v.size() / kMinPerBatch);
  if (k < 3) {
    MeanSe m = mean_se(v);
    if (m.se) m.se = std::max(*m.se, floor);
    return m;
  }
  const std::size_t per = v.size() / k;
  std::vector<double> means;
  for (std::size_t b = 0; b < k; ++b) {
    double sum = 0;
    for (std::size_t i = b * per; i < (b + 1) * per; ++i) sum += v[i];
    means.push_back(sum / static_cast<double>(per));
  }
  MeanSe m = mean_se(v);
  const double kd = static_cast<double>(k);
  const double se_b = mean_se(means).se.value_or(0.0);  // s_b / sqrt(k)
  const double noise_var = std::max(se_b * se_b * kd - kd * kd * floor * floor, 0.0) / kd;
  m.se = std::sqrt(noise_var + floor * floor);
  return m;
}
Window window_of(const std::vector<SampleRow>& rows, double from_s, double to_s) {
  Window w;
  for (const auto& r : rows) {
    // A sample covers the interval before its tick: only those wholly inside the window.
    if (!r.interval_s || r.t_s - *r.interval_s < from_s - 1e-6 || r.t_s > to_s + 1e-6 ||
        !r.net_pulses || !r.rate_dph || !(*r.interval_s > 0) || (r.flags & kBoardFault) != 0 ||
        (r.flags & kSafeHold) != 0)
      continue;
    w.pps.push_back(static_cast<double>(*r.net_pulses) / *r.interval_s);
    w.span_s += *r.interval_s;
    w.rate_dph.push_back(*r.rate_dph);
    if (r.temp_c) w.temp_c.push_back(*r.temp_c);
  }
  return w;
}

/// A point of a step's schedule with its event (nullptr: no window was measured, a kill or a
/// hold across it) and the samples of its window (none without an event).
struct WalkedPoint {
  AcceptancePoint scheduled;
  const PointEvent* event = nullptr;
  Window window;
};

/// The step's schedule walked point by point: what ladders and positions both start from.
std::vector<WalkedPoint> walk_schedule(const Step& s, const std::map<int, PointEvent>& events,
                                       const std::vector<SampleRow>& rows) {
  std::vector<WalkedPoint> out;
  for (const auto& sp : acceptance_schedule(s)) {
    WalkedPoint w{sp};
    if (const auto it = events.find(sp.index); it != events.end()) {
      w.event = &it->second;
      w.window = window_of(rows, it->second.measure_s, it->second.end_s);
    }
    out.push_back(std::move(w));
  }
  return out;
}

/// The mean of sensor A over the temperatures a step kept, C; NaN when it kept none.
double mean_temp_c(const std::vector<double>& temps) {
  return temps.empty() ? std::nan("") : mean_se(temps).mean;
}

/// The temperature a ladder's scale factor belongs to: the slope K = sum (x_i - xm) y_i / Sxx
/// of a gyro whose K drifts with its temperature T_i over the ladder (the later, faster points
/// warmer or colder) is, to first order in the drift, K(T_eff) with T_eff = sum (x_i - xm)^2 T_i
/// / Sxx: the fast points' temperature, not the mean over the windows (which put the plateaus'
/// K off their temperature by 0.15 ppm, 9 SE, on the shipped protocol's cold and hot ladders).
/// `points`/`temps_c`: the points the fit takes (in tolerance) and each one's mean sensor A.
double slope_temp_c(const std::vector<comp::LadderPoint>& points,
                    const std::vector<double>& temps_c) {
  double xm = 0, n = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i].rate_in_tolerance && std::isfinite(temps_c[i]))
      xm += comp::ladder_input_arcsec_per_s(points[i]), n += 1;
  if (n < 2) return std::nan("");
  xm /= n;
  double sxx = 0, sxt = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].rate_in_tolerance || !std::isfinite(temps_c[i])) continue;
    const double d = comp::ladder_input_arcsec_per_s(points[i]) - xm;
    sxx += d * d, sxt += d * d * temps_c[i];
  }
  return sxx > 0 ? sxt / sxx : std::nan("");
}

LadderFigures ladder_of(const Step& s, int index, const std::map<int, PointEvent>& events,
                        const std::vector<SampleRow>& rows, const RunSlot& slot) {
  LadderFigures f;
  f.step_index = index;
  f.label = s.label;
  std::vector<comp::LadderPoint> points;
  std::vector<double> point_temps_c;
  for (const auto& w : walk_schedule(s, events, rows)) {
    ++f.points;
    if (w.event == nullptr) {
      ++f.missing;
      continue;
    }
    const MeanSe out = batch_mean_se(w.window.pps, w.window.quantization_pps());
    comp::LadderPoint p;
    // The table turns about up: an input axis down senses it negated (its Earth rate is the
    // slot's, already signed).
    p.table_rate_dps =
        (slot.axis == "down" ? -1.0 : 1.0) * w.event->table_mean.value_or(w.scheduled.demand);
    p.earth_rate_dph = slot.earth_rate_dph;
    p.output_pps = out.mean;
    p.output_se_pps = out.se.value_or(0.0);
    p.rate_in_tolerance = w.event->held && out.se && *out.se > 0;
    points.push_back(p);
    point_temps_c.push_back(mean_temp_c(w.window.temp_c));
  }
  f.temp_c = slope_temp_c(points, point_temps_c);
  f.fit = comp::analyze_rate_ladder(points);
  // A gyro that did not follow the table gives a "scale factor" that is none (its K w far
  // from 1): not computed, never released.
  if (f.fit && slot.pulse_weight_arcsec > 0) {
    const double kw = f.fit->sf_pulse_per_arcsec * slot.pulse_weight_arcsec;
    if (!(std::abs(kw - 1.0) <= comp::kMaxScaleFactorDeviation))
      f.fit = comp::NotComputed{fmt::format(
          "K w = {:.6g} is not 1 within {:g} %: the gyro's output did not follow the table "
          "(nominal pulse weight w = {:g} arcsec)",
          kw, 100 * comp::kMaxScaleFactorDeviation, slot.pulse_weight_arcsec)};
  }
  return f;
}

PositionFigures positions_of(const Step& s, int index, const std::map<int, PointEvent>& events,
                             const std::vector<SampleRow>& rows, const RunSlot& slot) {
  PositionFigures f;
  f.step_index = index;
  f.label = s.label;
  std::vector<comp::PositionPoint> points;
  std::vector<double> temps;
  for (const auto& w : walk_schedule(s, events, rows)) {
    ++f.points;
    const MeanSe out =
        batch_mean_se(w.window.rate_dph, w.window.quantization_pps() * slot.pulse_weight_arcsec);
    if (w.event == nullptr || !w.event->held || !out.se || !(*out.se > 0)) {
      ++f.excluded;
      continue;
    }
    points.push_back({w.event->table_mean.value_or(w.scheduled.demand), out.mean, *out.se});
    f.angles_deg.push_back(points.back().table_angle_deg);
    temps.insert(temps.end(), w.window.temp_c.begin(), w.window.temp_c.end());
  }
  f.temp_c = mean_temp_c(temps);
  // The axis is up: its Earth rate is Omega sin(phi) (earth_rate.hpp), so the site's latitude
  // is the one the run's slot was given.
  const double s_phi = std::clamp(slot.earth_rate_dph / comp::kEarthRateDph, -1.0, 1.0);
  f.fit = comp::analyze_positions_axis_vertical(points, {std::asin(s_phi) * 180.0 / M_PI, 0.0});
  return f;
}

/// One turn-on's bias in kTurnOnBinS bins from its power-on, deg/h (rate - Earth rate).
TurnOnCurve turn_on_bins(const std::vector<SampleRow>& rows, const PointEvent& e,
                         double earth_dph) {
  TurnOnCurve b;
  for (double from = e.measure_s; from + kTurnOnBinS <= e.end_s + 1e-9; from += kTurnOnBinS) {
    const MeanSe m = mean_se(window_of(rows, from, from + kTurnOnBinS).rate_dph);
    if (m.n * 2 < kTurnOnBinS) continue;  // a bin with under half its samples is no bin
    b.t_s.push_back(from - e.measure_s + kTurnOnBinS / 2);
    b.bias_dph.push_back(m.mean - earth_dph);
  }
  return b;
}

/// The warm-up band: three times the sd of the bins in the final windows (pooled over the
/// turn-ons, about each one's final mean), so noise alone leaves a settled gyro inside it; never
/// narrower than three times a bin's own quantization sd (`bin_quantization_dph`: a quiet gyro's
/// bins can all read the same count, an sd of 0 and no band at all).
double noise_band_dph(const std::vector<TurnOnCurve>& all, const comp::TurnOnWindows& w,
                      double bin_quantization_dph) {
  double ss = 0;
  std::size_t n = 0, groups = 0;
  for (const auto& b : all) {
    std::vector<double> v;
    for (std::size_t i = 0; i < b.t_s.size(); ++i)
      if (b.t_s[i] >= w.final_start_s && b.t_s[i] <= w.final_end_s) v.push_back(b.bias_dph[i]);
    const MeanSe m = mean_se(v);
    for (double x : v) ss += (x - m.mean) * (x - m.mean);
    n += v.size();
    groups += v.empty() ? 0 : 1;
  }
  const double sd = n > groups ? std::sqrt(ss / static_cast<double>(n - groups)) : 0.0;
  return 3.0 * std::max(sd, bin_quantization_dph);
}

void turn_ons_of(const Step& s, const std::map<int, PointEvent>& events,
                 const std::vector<SampleRow>& rows, const RunSlot& slot, SerialAcceptance& out) {
  std::vector<TurnOnCurve> bins;
  for (const auto& [point, e] : events)  // a turn-on a hold or a kill cut short is left out
    if (e.held) bins.push_back(turn_on_bins(rows, e, slot.earth_rate_dph));
  // After warm-up: the bias over the second half of the powered time, the final value over
  // its last third.
  comp::TurnOnWindows w;
  w.bias_start_s = s.dwell_s / 2;
  w.bias_end_s = s.dwell_s;
  w.final_start_s = s.dwell_s * 2 / 3;
  w.final_end_s = s.dwell_s;
  const auto quantization_dph = [&](double window_s) {
    return slot.pulse_weight_arcsec * mean_quantization_pps(window_s);
  };
  w.band_dph = noise_band_dph(bins, w, quantization_dph(kTurnOnBinS));
  w.bias_quantization_dph = quantization_dph(w.bias_end_s - w.bias_start_s);
  out.turn_on_band_dph = w.band_dph;
  std::vector<comp::TurnOnSeries> series;
  for (const auto& b : bins) series.push_back({b.t_s, b.bias_dph});
  out.turn_on = comp::analyze_turn_ons(series, w);
  out.turn_on_curves = std::move(bins);
}

void analyze_step(const Protocol& p, int index, const StepPoints& events,
                  const std::vector<SampleRow>& rows, const RunSlot& slot, SerialAcceptance& out) {
  const Step& s = p.steps[static_cast<std::size_t>(index)];
  static const std::map<int, PointEvent> kNone;
  const auto it = events.find(index);
  const auto& mine = it == events.end() ? kNone : it->second;
  if (s.kind == StepKind::rate_ladder) {
    LadderFigures f = ladder_of(s, index, mine, rows, slot);
    if (slot.axis != "up" && slot.axis != "down")
      f.fit = comp::NotComputed{
          "a ladder is analysed for an input axis along the table's (up or "
          "down); this one is " +
          slot.axis};
    out.ladders.push_back(std::move(f));
  } else if (s.kind == StepKind::positions) {
    if (slot.axis == "up")
      out.positions.push_back(positions_of(s, index, mine, rows, slot));
    else
      out.positions_note =
          "positions are analysed for an input axis up only (this one: " + slot.axis + ")";
  } else if (s.kind == StepKind::power_cycles) {
    turn_ons_of(s, mine, rows, slot, out);
  }
}

}  // namespace

std::vector<SerialAcceptance> run_acceptance(Store& store, std::int64_t run_id, double ref_temp_c) {
  std::vector<SerialAcceptance> out;
  const auto run = store.find_run(run_id);
  if (!run) return out;
  const Protocol p = parse_protocol(run->protocol_text, "run " + std::to_string(run_id));
  std::vector<int> steps;
  for (std::size_t i = 0; i < p.steps.size(); ++i)
    if (is_acceptance_step(p.steps[i].kind)) steps.push_back(static_cast<int>(i));
  if (steps.empty()) return out;
  const StepPoints events = point_events(store, run_id);
  for (const auto& slot : store.run_slots(run_id)) {
    SerialAcceptance a;
    a.serial = slot.serial;
    a.earth_rate_dph = slot.earth_rate_dph;
    const auto rows = store.samples(run_id, slot.serial, false);
    for (int i : steps) analyze_step(p, i, events, rows, slot, a);
    std::vector<comp::PlateauScaleFactor> plateaus;
    for (const auto& l : a.ladders)
      if (l.fit && std::isfinite(l.temp_c))
        plateaus.push_back({l.temp_c, l.fit->sf_pulse_per_arcsec, l.fit->sf_se_pulse_per_arcsec});
    if (plateaus.size() >= 2)
      a.sf_vs_temp = comp::fit_scale_factor_vs_temperature(plateaus, ref_temp_c);
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace station
