// The acceptance pages' data from the store: station/acceptance's figures, and what their
// structs do not carry (each turn-on's bins, the angles of the positions) from the run's
// acceptance_point events and samples.
#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>

#include "compensation/earth_rate.hpp"
#include "station/config/protocol.hpp"
#include "station/report/report_acceptance.hpp"

namespace station::report {
namespace {

/// One acceptance_point event's window and what the table did (acceptance_runner.cpp writes it).
struct Point {
  double demand = 0, measure_s = 0, end_s = 0;
  std::optional<double> table_mean;
  bool held = false;
};
using StepPoints = std::map<int, std::map<int, Point>>;  // step index -> point index -> event

StepPoints step_points(const std::vector<EventRow>& events) {
  StepPoints out;
  for (const auto& e : events) {
    if (e.kind != "acceptance_point" || !e.data_json) continue;
    const auto j = nlohmann::json::parse(*e.data_json, nullptr, false);
    if (!j.is_object() || !j.contains("step_index") || !j.contains("point")) continue;
    Point p;
    p.demand = j.value("demand", 0.0);
    p.measure_s = j.value("measure_s", 0.0);
    p.end_s = j.value("end_s", 0.0);
    if (j.contains("table_mean") && j["table_mean"].is_number()) p.table_mean = j["table_mean"];
    p.held = j.value("held", false);
    out[j.value("step_index", -1)][j.value("point", 0)] = p;  // a resumed run's later one wins
  }
  return out;
}

/// A turn-on's bias in kTurnOnBinS bins from its power-up, as acceptance_run.cpp bins it for the
/// analysis (whose result keeps the figures, not the bins): the samples wholly inside a bin, with
/// a count and a rate, not flagged board fault or safe hold; a bin under half full is none.
/// warmup_figure checks these bins give the analysis' own warm-up times.
WarmupCurve warmup_curve(const std::vector<SampleRow>& rows, const Point& p, double earth_dph) {
  WarmupCurve c;
  auto it = std::lower_bound(rows.begin(), rows.end(), p.measure_s,
                             [](const SampleRow& r, double t) { return r.t_s < t; });
  for (double from = p.measure_s; from + kTurnOnBinS <= p.end_s + 1e-9; from += kTurnOnBinS) {
    double sum = 0;
    std::size_t n = 0;
    for (; it != rows.end() && it->t_s <= from + kTurnOnBinS + 1e-6; ++it) {
      const auto& r = *it;
      if (!r.interval_s || r.t_s - *r.interval_s < from - 1e-6 || !r.net_pulses || !r.rate_dph ||
          !(*r.interval_s > 0) || (r.flags & (kBoardFault | kSafeHold)) != 0)
        continue;
      sum += *r.rate_dph;
      ++n;
    }
    if (n * 2 < kTurnOnBinS) continue;
    c.t_s.push_back(from - p.measure_s + kTurnOnBinS / 2);
    c.bias_dph.push_back(compensation::bias_dph(sum / static_cast<double>(n), earth_dph));
  }
  return c;
}

/// The angles of a positions step's held points in point order: the ones its fit took
/// (acceptance_run.cpp), each the table's mean over its window, else the demand.
std::vector<double> held_angles(const std::map<int, Point>& points) {
  std::vector<double> out;
  for (const auto& [index, p] : points)
    if (p.held) out.push_back(p.table_mean.value_or(p.demand));
  return out;
}

}  // namespace

std::vector<SerialAcceptanceReport> load_acceptance(Store& store, const RunRecord& run) {
  std::vector<SerialAcceptanceReport> out;
  if (run.protocol_text.empty()) return out;  // a run stored without its protocol
  auto figures = run_acceptance(store, run.id);
  if (figures.empty()) return out;
  const Protocol protocol = parse_protocol(run.protocol_text, fmt::format("run {}", run.id));
  const StepPoints points = step_points(store.event_rows(run.id));
  static const std::map<int, Point> kNone;
  const auto of_step = [&](int step) -> const std::map<int, Point>& {
    const auto it = points.find(step);
    return it == points.end() ? kNone : it->second;
  };
  // The analysis takes the last power_cycles step's turn-ons (each step's replaces the last's).
  int power_step = -1;
  for (std::size_t i = 0; i < protocol.steps.size(); ++i)
    if (protocol.steps[i].kind == StepKind::power_cycles) power_step = static_cast<int>(i);
  const auto slots = store.run_slots(run.id);
  for (auto& f : figures) {
    SerialAcceptanceReport s;
    const auto slot = std::find_if(slots.begin(), slots.end(),
                                   [&](const RunSlot& r) { return r.serial == f.serial; });
    if (f.turn_on && slot != slots.end()) {
      const auto rows = store.samples(run.id, f.serial, false);
      for (const auto& [index, p] : of_step(power_step))
        if (p.held) s.warmups.push_back(warmup_curve(rows, p, slot->earth_rate_dph));
    }
    for (const auto& p : f.positions) {
      auto angles = held_angles(of_step(p.step_index));
      if (!p.fit || angles.size() != p.fit->fit.positions) angles.clear();
      s.position_angles_deg.push_back(std::move(angles));
    }
    s.figures = std::move(f);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace station::report
