// A run's acceptance figures from its acceptance_point events and its samples.
#include "station/acceptance/acceptance_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "compensation/acceptance_windows.hpp"
#include "compensation/earth_rate.hpp"
#include "station/config/acceptance_steps.hpp"
#include "station/config/config.hpp"
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

/// The samples of [from_s, to_s) with a rate: pulses per second, rate deg/h, sensor A and each
/// sample's span.
struct Window {
  std::vector<double> pps, rate_dph, temp_c, spans_s;
  double span_s = 0;  ///< the time the samples cover (their intervals), s
  /// The series in pulses/s (`in_dph` false) or deg/h, for the window statistics.
  comp::WindowSeries series(bool in_dph) const { return {in_dph ? rate_dph : pps, spans_s}; }
};

Window window_of(const std::vector<SampleRow>& rows, double from_s, double to_s) {
  Window w;
  for (const auto& r : rows) {
    // A sample covers the interval before its tick: only those wholly inside the window.
    if (!r.interval_s || r.t_s - *r.interval_s < from_s - 1e-6 || r.t_s > to_s + 1e-6 ||
        !r.net_pulses || !r.rate_dph || !(*r.interval_s > 0) || (r.flags & kBoardFault) != 0 ||
        (r.flags & kSafeHold) != 0)
      continue;
    w.pps.push_back(static_cast<double>(*r.net_pulses) / *r.interval_s);
    w.spans_s.push_back(*r.interval_s);
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
    WalkedPoint w{sp, nullptr, {}};
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

/// A measuring window's mean and its error from the serial's white noise density (in the
/// series' unit squared times s) and its two ends' rounding (acceptance_windows.hpp); empty
/// without a density or with fewer than 2 samples.
std::optional<comp::WindowMean> point_mean(const Window& w, bool in_dph,
                                           std::optional<double> white, double pulse_unit) {
  if (!white || w.spans_s.size() < 2) return std::nullopt;
  return comp::window_mean(w.series(in_dph), *white, pulse_unit);
}

/// A power_cycles step's windows after warm-up: the bias over the second half of the powered
/// time, the final value over its last third and at least its last two whole bins (s since
/// power-on). A third can hold one bin's centre: on_s = 330 s has bins to 300 s, centres at 210
/// and 270 s, its third 220..330 s. The bins' centres are kTurnOnBinS apart from kTurnOnBinS/2,
/// so from the second-last whole bin's start both last centres are inside; with the parser's
/// shortest powered time (four bins) the second half holds two as well.
comp::TurnOnWindows turn_on_windows(const Step& s) {
  comp::TurnOnWindows w;
  w.bias_start_s = s.dwell_s / 2;
  w.bias_end_s = s.dwell_s;
  const double whole_bins = std::floor(s.dwell_s / kTurnOnBinS);
  w.final_start_s = std::min(s.dwell_s * 2 / 3, (whole_bins - 2) * kTurnOnBinS);
  w.final_end_s = s.dwell_s;
  return w;
}

/// The windows of step `s` that estimate the gyro's white noise: each point the table held
/// (ladders, positions), each whole turn-on's final-value window (power cycles).
std::vector<Window> noise_windows(const Step& s, const std::map<int, PointEvent>& events,
                                  const std::vector<SampleRow>& rows) {
  std::vector<Window> out;
  if (s.kind == StepKind::power_cycles) {
    const auto w = turn_on_windows(s);
    for (const auto& [point, e] : events)
      if (e.held) out.push_back(window_of(rows, e.measure_s + w.final_start_s, e.end_s));
    return out;
  }
  for (auto& w : walk_schedule(s, events, rows))
    if (w.event != nullptr && w.event->held) out.push_back(std::move(w.window));
  return out;
}

/// Whether a rate ladder measures this slot's gyro: an input axis along the table's axis (up or
/// down). A horizontal axis turning with the table sees the Earth rate's horizontal component
/// swing through +-W cos(lat) over a ladder's window, so its ladder is neither analysed nor a
/// window of constant input for the noise.
bool ladder_measures(const RunSlot& slot) {
  return slot.axis == "up" || slot.axis == "down";
}

/// The serial's white rate noise density, pulses^2/s: pooled over the measuring windows of all
/// its acceptance steps (noise_windows; acceptance_windows.hpp: the gyro's N is one number, and
/// one window alone estimates it poorly), each a window of constant input (ladder_measures).
std::optional<double> serial_white_density(const Protocol& p, const std::vector<int>& steps,
                                           const StepPoints& events,
                                           const std::vector<SampleRow>& rows,
                                           const RunSlot& slot) {
  std::vector<Window> windows;
  for (int i : steps) {
    const auto it = events.find(i);
    if (it == events.end()) continue;
    if (p.steps[static_cast<std::size_t>(i)].kind == StepKind::rate_ladder &&
        !ladder_measures(slot))
      continue;
    for (auto& w : noise_windows(p.steps[static_cast<std::size_t>(i)], it->second, rows))
      windows.push_back(std::move(w));
  }
  std::vector<comp::WindowSeries> series;
  for (const auto& w : windows) series.push_back(w.series(false));
  return comp::pooled_white_density(series, 1.0);
}

void hold_to_nominal(LadderFigures& f, const RunSlot& slot);

LadderFigures ladder_of(const Step& s, int index, const std::map<int, PointEvent>& events,
                        const std::vector<SampleRow>& rows, const RunSlot& slot,
                        std::optional<double> white_pps2_s) {
  LadderFigures f;
  f.step_index = index;
  f.label = s.label;
  std::vector<comp::LadderPoint> points;
  for (const auto& w : walk_schedule(s, events, rows)) {
    ++f.points;
    if (w.event == nullptr) {
      ++f.missing;
      continue;
    }
    const auto out = point_mean(w.window, false, white_pps2_s, 1.0);
    comp::LadderPoint p;
    // The table turns about up: an input axis down senses it negated (its Earth rate is the
    // slot's, already signed).
    p.table_rate_dps =
        (slot.axis == "down" ? -1.0 : 1.0) * w.event->table_mean.value_or(w.scheduled.demand);
    p.earth_rate_dph = slot.earth_rate_dph;
    p.output_pps = out ? out->mean : std::nan("");
    p.output_se_pps = out ? out->se : 0.0;
    p.rate_in_tolerance = w.event->held && out;
    p.temp_c = mean_temp_c(w.window.temp_c);
    points.push_back(p);
  }
  // K's temperature is the fast points' (scale_factor.hpp: the windows' mean put the shipped
  // protocol's cold and hot K off their temperature by 0.15 ppm, 9 SE, on drifting plateaus).
  f.temp_c = comp::ladder_slope_temp_c(points);
  f.fit = comp::analyze_rate_ladder(points);
  f.measured = std::move(points);
  hold_to_nominal(f, slot);
  return f;
}

/// A gyro that did not follow the table gives a "scale factor" that is none (its K w far from
/// 1): not computed, never released.
void hold_to_nominal(LadderFigures& f, const RunSlot& slot) {
  if (f.fit && slot.pulse_weight_arcsec > 0) {
    const double kw = f.fit->sf_pulse_per_arcsec * slot.pulse_weight_arcsec;
    if (!(std::abs(kw - 1.0) <= comp::kMaxScaleFactorDeviation))
      f.fit = comp::NotComputed{fmt::format(
          "K w = {:.6g} is not 1 within {:g} %: the gyro's output did not follow the table "
          "(nominal pulse weight w = {:g} arcsec)",
          kw, 100 * comp::kMaxScaleFactorDeviation, slot.pulse_weight_arcsec)};
  }
}

/// The site's latitude for the positions of a horizontal axis: the run's configuration
/// snapshot's (what its slots' Earth rates came from), or why there is none.
struct SiteLatitude {
  std::optional<double> deg;
  std::string why;
};

SiteLatitude run_latitude(const RunRecord& run) {
  try {
    return {parse_station_config(run.config_text, "run " + std::to_string(run.id) + " config")
                .latitude_deg,
            {}};
  } catch (const std::exception& e) {
    return {std::nullopt, std::string("the run's configuration gives no latitude: ") + e.what()};
  }
}

/// The slot's horizontal heading (positions.hpp via heading_error_rad's conventions), empty for
/// an axis up or down or one that does not read.
std::optional<double> slot_heading_deg(const RunSlot& slot) {
  try {
    return comp::axis_heading_deg(slot.axis);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// The horizontal axis's figures (heading_error_rad states the conventions): the zero mark at
/// north, the axis at table angle -heading; no known bias (the table turns about up only, so
/// the bias and the axis's elevation are one constant: positions.hpp).
void analyze_horizontal(const std::vector<comp::PositionPoint>& points, double heading_deg,
                        const SiteLatitude& latitude, PositionFigures& f) {
  f.nominal_heading_deg = heading_deg;
  f.fit = comp::NotComputed{"the input axis is horizontal"};
  if (!latitude.deg) {
    f.horizontal = comp::NotComputed{latitude.why};
    return;
  }
  f.horizontal =
      comp::analyze_positions_axis_horizontal(points, {*latitude.deg, 0.0}, -heading_deg);
}

PositionFigures positions_of(const Step& s, int index, const std::map<int, PointEvent>& events,
                             const std::vector<SampleRow>& rows, const RunSlot& slot,
                             std::optional<double> white_pps2_s, const SiteLatitude& latitude) {
  PositionFigures f;
  f.step_index = index;
  f.label = s.label;
  std::vector<comp::PositionPoint> points;
  std::vector<double> temps;
  for (const auto& w : walk_schedule(s, events, rows)) {
    ++f.points;
    // In deg/h: one pulse per second is the pulse weight (arcsec/s = deg/h).
    const double w_arcsec = slot.pulse_weight_arcsec;
    const auto out = white_pps2_s
                         ? point_mean(w.window, true, *white_pps2_s * w_arcsec * w_arcsec, w_arcsec)
                         : std::nullopt;
    if (w.event == nullptr || !w.event->held || !out) {
      ++f.excluded;
      continue;
    }
    points.push_back({w.event->table_mean.value_or(w.scheduled.demand), out->mean, out->se});
    f.angles_deg.push_back(points.back().table_angle_deg);
    temps.insert(temps.end(), w.window.temp_c.begin(), w.window.temp_c.end());
  }
  f.temp_c = mean_temp_c(temps);
  if (const auto heading = slot_heading_deg(slot)) {
    analyze_horizontal(points, *heading, latitude, f);
    return f;
  }
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

/// The warm-up band, deg/h: three times the sd of a bin's deviation from its turn-on's final
/// value, sqrt((S / bin + q(bin)^2) (1 + 1/m)), S the serial's white noise density in deg/h
/// (acceptance_windows.hpp: pooled over all its measuring windows, so noise alone leaves a
/// settled gyro inside it with probability 0.997 per bin), q(bin) the bin's two ends' rounding
/// and m the bins of the final value's mean. Not the sd of the final bins themselves: three
/// bins a turn-on (4 dof with two turn-ons) put the band anywhere, and a quantized bin two
/// pulses off (0.05 deg/h) then read "outside" by noise (warm-ups of 270..410 s for a true 0
/// in 6 of 48 simulated gyros of tests/sessions/session_acceptance.toml, seeds 1..6).
double noise_band_dph(std::optional<double> white_dph2_s, double bin_quantization_dph,
                      double final_bins) {
  const double bin_var =
      white_dph2_s.value_or(0.0) / kTurnOnBinS + bin_quantization_dph * bin_quantization_dph;
  return 3.0 * std::sqrt(bin_var * (1.0 + 1.0 / std::max(final_bins, 1.0)));
}

void turn_ons_of(const Step& s, int index, const std::map<int, PointEvent>& events,
                 const std::vector<SampleRow>& rows, const RunSlot& slot,
                 std::optional<double> white_pps2_s, SerialAcceptance& out) {
  TurnOnStep t;
  t.step_index = index;
  t.label = s.label;
  std::vector<double> temps;
  for (const auto& [point, e] : events) {  // a turn-on a hold or a kill cut short is left out
    if (!e.held) continue;
    t.curves.push_back(turn_on_bins(rows, e, slot.earth_rate_dph));
    const auto w = window_of(rows, e.measure_s, e.end_s).temp_c;
    temps.insert(temps.end(), w.begin(), w.end());
  }
  t.temp_c = mean_temp_c(temps);
  comp::TurnOnWindows w = turn_on_windows(s);
  const double w_arcsec = slot.pulse_weight_arcsec;
  const auto quantization_dph = [&](double window_s) {
    return w_arcsec * comp::mean_quantization_pps(window_s);
  };
  std::optional<double> white_dph2_s;
  if (white_pps2_s) white_dph2_s = *white_pps2_s * w_arcsec * w_arcsec;
  w.band_dph = noise_band_dph(white_dph2_s, quantization_dph(kTurnOnBinS),
                              (w.final_end_s - w.final_start_s) / kTurnOnBinS);
  w.bias_quantization_dph = quantization_dph(w.bias_end_s - w.bias_start_s);
  t.band_dph = w.band_dph;
  std::vector<comp::TurnOnSeries> series;
  for (const auto& b : t.curves) series.push_back({b.t_s, b.bias_dph});
  t.result = comp::analyze_turn_ons(series, w);
  // The serial's headline turn-on figures are its first power_cycles step's (the report, the
  // store and the fleet carry them); every step's are in turn_on_steps and judged.
  if (!out.turn_on) {
    out.turn_on = t.result;
    out.turn_on_curves = t.curves;
    out.turn_on_band_dph = t.band_dph;
  }
  out.turn_on_steps.push_back(std::move(t));
}

void analyze_step(const Protocol& p, int index, const StepPoints& events,
                  const std::vector<SampleRow>& rows, const RunSlot& slot,
                  std::optional<double> white_pps2_s, const SiteLatitude& latitude,
                  SerialAcceptance& out) {
  const Step& s = p.steps[static_cast<std::size_t>(index)];
  static const std::map<int, PointEvent> kNone;
  const auto it = events.find(index);
  const auto& mine = it == events.end() ? kNone : it->second;
  if (s.kind == StepKind::rate_ladder) {
    LadderFigures f = ladder_of(s, index, mine, rows, slot, white_pps2_s);
    if (!ladder_measures(slot))
      f.fit = comp::NotComputed{
          "a ladder is analysed for an input axis along the table's (up or "
          "down); this one is " +
          slot.axis};
    out.ladders.push_back(std::move(f));
  } else if (s.kind == StepKind::positions) {
    if (slot.axis == "up" || slot_heading_deg(slot))
      out.positions.push_back(positions_of(s, index, mine, rows, slot, white_pps2_s, latitude));
    else
      out.positions_note =
          "positions are analysed for an input axis up or horizontal (this one: " + slot.axis + ")";
  } else if (s.kind == StepKind::power_cycles) {
    turn_ons_of(s, index, mine, rows, slot, white_pps2_s, out);
  }
}

/// The scale factor against temperature over the serial's ladders (two or more).
void fit_across_plateaus(SerialAcceptance& a, double ref_temp_c) {
  std::vector<comp::PlateauScaleFactor> plateaus;
  for (const auto& l : a.ladders)
    if (l.fit && std::isfinite(l.temp_c))
      plateaus.push_back({l.temp_c, l.fit->sf_pulse_per_arcsec, l.fit->sf_se_pulse_per_arcsec});
  a.sf_vs_temp.reset();
  if (plateaus.size() >= 2)
    a.sf_vs_temp = comp::fit_scale_factor_vs_temperature(plateaus, ref_temp_c);
}

}  // namespace

const comp::ProjectionFit* positions_projection(const PositionFigures& p, std::string* why) {
  if (p.nominal_heading_deg) {
    if (p.horizontal) return &p.horizontal->fit;
    if (why) *why = p.horizontal.error();
    return nullptr;
  }
  if (p.fit) return &p.fit->fit;
  if (why) *why = p.fit.error();
  return nullptr;
}

double positions_bias_dph(const PositionFigures& p) {
  if (p.nominal_heading_deg) return p.horizontal ? p.horizontal->bias_if_level_dph : 0.0;
  return p.fit ? p.fit->bias_dph : 0.0;
}

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
  const auto slots = store.run_slots(run_id);
  // Only a horizontal axis needs the latitude (a vertical one's comes from its Earth rate).
  const bool horizontal = std::any_of(
      slots.begin(), slots.end(), [](const RunSlot& s) { return slot_heading_deg(s).has_value(); });
  const SiteLatitude latitude = horizontal ? run_latitude(*run) : SiteLatitude{};
  for (const auto& slot : slots) {
    SerialAcceptance a;
    a.serial = slot.serial;
    a.earth_rate_dph = slot.earth_rate_dph;
    const auto rows = store.samples(run_id, slot.serial, false);
    const auto white_pps2_s = serial_white_density(p, steps, events, rows, slot);
    for (int i : steps) analyze_step(p, i, events, rows, slot, white_pps2_s, latitude, a);
    fit_across_plateaus(a, ref_temp_c);
    // A drifting plateau's ladder brought to its slope's temperature with the run's own TC
    // (scale_factor.hpp, "A drifting plateau"), then K against temperature again.
    if (a.sf_vs_temp && *a.sf_vs_temp) {
      const comp::LadderTemperatureModel tc{(*a.sf_vs_temp)->tc_ppm_per_c,
                                            (*a.sf_vs_temp)->tc_se_ppm_per_c};
      for (auto& l : a.ladders) {
        if (!l.fit) continue;
        l.fit = comp::analyze_rate_ladder(l.measured, tc);
        hold_to_nominal(l, slot);
      }
      fit_across_plateaus(a, ref_temp_c);
    }
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace station
