// Acceptance steps: their keys and their schedules.
#include "station/config/acceptance_steps.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "station/config/toml_reader.hpp"

namespace station {
namespace {

// Bounds: a rate table's rates (the ACUTROL3000's rate loop reaches 1000 deg/s and more; a
// gyro's full scale is a few hundred), a week for any time (as the other steps), no more points
// than a report can draw.
constexpr double kMaxRateDps = 1000.0;
constexpr double kMaxAngleDeg = 360.0;
constexpr double kMaxTimeS = 7 * 86400.0;
constexpr std::size_t kMaxPoints = 64;

double time_in(const TomlView& v, const char* key, double fallback, double lo) {
  const double t = v.opt_number_in(key, 0.0, kMaxTimeS, "s").value_or(fallback);
  if (t < lo) throw v.error(key, fmt::format("{} s is shorter than {} s", t, lo));
  return t;
}

// The first pair of entries closer than `resolution` by `distance`, as "entries I and J: A and B
// UNIT are one ...": a repeated point measures nothing new and is counted twice in the fit.
template <typename Distance>
void refuse_repeats(const TomlView& v, const char* key, const std::vector<double>& values,
                    double resolution, Distance distance, const char* what) {
  for (std::size_t j = 1; j < values.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      if (distance(values[i], values[j]) < resolution)
        throw v.error(key, fmt::format("entries {} and {}: {} and {} are one {}", i, j, values[i],
                                       values[j], what));
    }
  }
}

void read_ladder(const TomlView& v, Step& s) {
  v.allow_only({"type", "label", "rates_dps", "settle_s", "dwell_s", "accel_dps2",
                "rate_tolerance_dps", "timeout_s"});
  s.rates_dps = v.number_array_in("rates_dps", 0.0, kMaxRateDps, "deg/s", kMaxPoints / 2);
  if (s.rates_dps.empty()) throw v.error("rates_dps", "missing (rate magnitudes, deg/s)");
  for (std::size_t i = 0; i < s.rates_dps.size(); ++i) {
    if (!(s.rates_dps[i] > 0))
      throw v.error("rates_dps", fmt::format("entry {}: a rate must be above 0 deg/s", i));
  }
  if (s.rates_dps.size() < 2)
    throw v.error("rates_dps", "needs at least 2 rates (4 points: a line and its residuals)");
  // The first sample in a window covers the second before it: settle at least two ticks so it
  // never holds the table's travel; a window of 10 s or more gives its mean an error.
  s.settle_s = time_in(v, "settle_s", 10.0, 2.0);
  s.dwell_s = time_in(v, "dwell_s", 60.0, 10.0);
  s.accel_dps2 = v.opt_number_in("accel_dps2", 0.01, 1e4, "deg/s^2").value_or(10.0);
  s.rate_tolerance_dps = v.opt_number_in("rate_tolerance_dps", 1e-6, 100.0, "deg/s").value_or(0.05);
  refuse_repeats(
      v, "rates_dps", s.rates_dps, s.rate_tolerance_dps,
      [](double a, double b) { return std::abs(a - b); },
      fmt::format("rate (closer than rate_tolerance_dps {:g} deg/s: the table's read-back cannot "
                  "tell them apart)",
                  s.rate_tolerance_dps)
          .c_str());
}

void read_positions(const TomlView& v, Step& s) {
  v.allow_only({"type", "label", "angles_deg", "settle_s", "dwell_s", "timeout_s"});
  s.angles_deg = v.number_array_in("angles_deg", -kMaxAngleDeg, kMaxAngleDeg, "deg", kMaxPoints);
  if (s.angles_deg.size() < 3)
    throw v.error("angles_deg", "needs at least 3 angles (a cosine has 3 unknowns)");
  refuse_repeats(
      v, "angles_deg", s.angles_deg, kAngleToleranceDeg,
      [](double a, double b) { return std::abs(std::remainder(a - b, 360.0)); },
      fmt::format("angle (mod 360 deg, closer than the table's {:g} deg in-position tolerance)",
                  kAngleToleranceDeg)
          .c_str());
  s.settle_s = time_in(v, "settle_s", 30.0, 2.0);
  s.dwell_s = time_in(v, "dwell_s", 300.0, 10.0);
}

void read_power_cycles(const TomlView& v, Step& s) {
  v.allow_only({"type", "label", "cycles", "off_s", "on_s", "timeout_s"});
  s.cycles = static_cast<int>(
      v.opt_integer_in("cycles", 2, static_cast<long long>(kMaxPoints)).value_or(5));
  s.off_s = time_in(v, "off_s", 60.0, 1.0);
  // The turn-on's bias is the mean of the second half's 60 s bins, the warm-up needs bins before
  // it: four bins at least.
  s.dwell_s = time_in(v, "on_s", 1800.0, 240.0);
}

}  // namespace

bool is_acceptance_step(StepKind k) {
  return k == StepKind::rate_ladder || k == StepKind::positions || k == StepKind::power_cycles;
}

void read_acceptance_step(const TomlView& v, Step& s) {
  switch (s.kind) {
    case StepKind::rate_ladder:
      read_ladder(v, s);
      break;
    case StepKind::positions:
      read_positions(v, s);
      break;
    case StepKind::power_cycles:
      read_power_cycles(v, s);
      break;
    default:
      return;
  }
  if (const double d = acceptance_duration_s(s); d > kMaxTimeS)
    throw v.error("type", fmt::format("the step takes {:g} days, longer than the longest step "
                                      "(7 days)",
                                      d / 86400.0));
}

void check_tables_locked(const std::vector<Step>& steps, const std::string& path) {
  std::optional<std::size_t> released;  // a step that turned the table, not locked since
  for (std::size_t i = 0; i <= steps.size(); ++i) {
    const bool end = i == steps.size();
    if (!end && steps[i].kind == StepKind::lock_turntable) released.reset();
    if (released && (end || steps[i].kind == StepKind::record_start)) {
      const Step& r = steps[*released];
      throw InputError(fmt::format(
          "{}:{}: key 'step[{}].type': {} leaves the table released: a lock_turntable step must "
          "follow it before {}",
          path, r.line, *released, r.kind == StepKind::rate_ladder ? "rate_ladder" : "positions",
          end ? "the protocol ends" : "the record window opens"));
    }
    if (!end && (steps[i].kind == StepKind::rate_ladder || steps[i].kind == StepKind::positions))
      released = i;
  }
}

std::vector<AcceptancePoint> acceptance_schedule(const Step& s) {
  std::vector<AcceptancePoint> out;
  double t = 0, previous = 0;
  auto add = [&](double demand, double before_s) {
    const int i = static_cast<int>(out.size());
    out.push_back({i, demand, t, t + before_s, t + before_s + s.dwell_s});
    t = out.back().end_s;
  };
  switch (s.kind) {
    case StepKind::rate_ladder:
      for (double r : s.rates_dps) {
        for (double demand : {r, -r}) {
          add(demand, std::abs(demand - previous) / s.accel_dps2 + s.settle_s);
          previous = demand;
        }
      }
      break;
    case StepKind::positions:
      for (double a : s.angles_deg) add(a, s.settle_s);
      break;
    case StepKind::power_cycles:
      for (int c = 1; c <= s.cycles; ++c) add(c, s.off_s);
      break;
    default:
      break;
  }
  return out;
}

double acceptance_duration_s(const Step& s) {
  const auto points = acceptance_schedule(s);
  if (points.empty()) return 0;
  double end = points.back().end_s;
  if (s.kind == StepKind::rate_ladder)
    end += std::abs(points.back().demand) / s.accel_dps2 + s.settle_s;
  return end;
}

}  // namespace station
