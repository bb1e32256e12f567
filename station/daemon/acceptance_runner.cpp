// Acceptance steps: demands along the schedule, and what the table did over each window.
#include "station/daemon/acceptance_runner.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <string>

#include "drivers/registry/rate_limit.hpp"

namespace station {
namespace {

namespace dr = station::drivers;

// A point is measured over the whole window when the ticks it saw span all of it but the first
// and last tick (a run killed or held in the window measured less: left out).
constexpr double kWindowEdgeS = 2.0;

// A rate_ladder's demands against the table's limits: the configured ones, the dialect's own
// rate limit where it is lower (drivers/registry). Throws naming the step, the figure and the
// limit.
void check_table_limits(const Step& s, const std::string& where, const StationConfig& config) {
  if (s.kind != StepKind::rate_ladder || !config.turntable) return;
  const auto& spec = *config.turntable;
  if (const auto limit = dr::turntable_rate_limit(spec)) {
    const char* source =
        limit->dialects_own ? "its dialect's own limit" : "[turntable] max_rate_dps";
    for (std::size_t i = 0; i < s.rates_dps.size(); ++i) {
      if (s.rates_dps[i] > limit->dps)
        throw InputError(
            fmt::format("{}: rates_dps entry {}: {} deg/s is beyond the "
                        "turntable's rate limit {} deg/s ({}, model {})",
                        where, i, s.rates_dps[i], limit->dps, source, spec.model));
    }
  }
  if (spec.max_accel_dps2 && s.accel_dps2 > *spec.max_accel_dps2)
    throw InputError(
        fmt::format("{}: accel_dps2 {} deg/s^2 is beyond the turntable's "
                    "acceleration limit {} deg/s^2 ([turntable] max_accel_dps2): "
                    "the schedule would measure before the table reached its rate",
                    where, s.accel_dps2, *spec.max_accel_dps2));
}

}  // namespace

void check_acceptance_rig(const Protocol& protocol, const StationConfig& config,
                          bool has_turntable) {
  for (std::size_t i = 0; i < protocol.steps.size(); ++i) {
    const Step& s = protocol.steps[i];
    const auto where =
        fmt::format("{}:{}: step[{}] {}", protocol.path, s.line, i, to_string(s.kind));
    if ((s.kind == StepKind::rate_ladder || s.kind == StepKind::positions) && !has_turntable)
      throw InputError(where + ": this rig has no turntable");
    check_table_limits(s, where, config);
    if (s.kind != StepKind::power_cycles) continue;
    for (std::size_t k = 0; k < config.slots.size(); ++k) {
      if (config.slots[k].relay.empty())
        throw InputError(
            fmt::format("{}: slot {} has no relay (its [[slot]] relay = \"LINE\"): "
                        "its gyro could not be switched off",
                        where, k + 1));
    }
  }
}

void AcceptanceRunner::enter(const Step& step, int step_index, double started_s) {
  if (step_ != &step || step_index_ != step_index || started_s_ != started_s) {
    step_ = &step;
    step_index_ = step_index;
    started_s_ = started_s;
    points_ = acceptance_schedule(step);
    duration_s_ = acceptance_duration_s(step);
    current_ = -1;
    rested_ = false;
    stats_ = {};
    waited_s_ = 0;
    sent_s_.reset();
    arrived_ = true;
    holding_ = unreached_ = false;
  }
  // Entered again (after a safe hold: the table stopped, the relays off): the point being
  // measured lost part of its window and, for power cycles, its turn-on; a move under way has
  // its whole deadline again from the demand sent anew.
  if (current_ >= 0 && stats_.first_s) cut_ = true;
  if (!arrived_) sent_s_.reset();
  resend_ = true;
}

AcceptanceActions AcceptanceRunner::leave() {
  AcceptanceActions a;
  if (step_ == nullptr) return a;
  if (current_ >= 0) {
    cut_ = true;
    close(points_[static_cast<std::size_t>(current_)], a);
  }
  current_ = -1;
  rest(a);
  step_ = nullptr;
  return a;
}

void AcceptanceRunner::send(const AcceptancePoint& p, double t_s, AcceptanceActions& a) {
  const double in_s = schedule_s(t_s);
  switch (step_->kind) {
    case StepKind::rate_ladder:
      a.table = dr::TurntableCommand{dr::TurntableMode::rate, std::nullopt, p.demand, false};
      break;
    case StepKind::positions:
      a.table = dr::TurntableCommand{dr::TurntableMode::position, p.demand, std::nullopt, false};
      if (!resend_ || current_ != p.index) {  // a new point: its move is waited for
        sent_s_ = t_s;
        arrived_ = holding_ = unreached_ = false;
      } else if (!arrived_) {
        sent_s_ = t_s;  // sent again after a hold
      }
      break;
    case StepKind::power_cycles:
      power_on_ = in_s >= p.measure_s;
      a.gyro_power = power_on_;
      break;
    default:
      break;
  }
}

void AcceptanceRunner::wait_for_table(const AcceptancePoint& p, double t_s,
                                      const TableObservation& table) {
  if (step_->kind != StepKind::positions) return;
  if (!arrived_) {
    const bool there =
        table.in_position && table.angle_deg &&
        std::abs(std::remainder(*table.angle_deg - p.demand, 360.0)) <= kAngleToleranceDeg;
    unreached_ = !there && sent_s_ && t_s - *sent_s_ > kPositionMoveDeadlineS;
    arrived_ = there || unreached_;
    // Held at the window's start while the table moved: settle_s from its arrival.
    if (there && holding_) waited_s_ = t_s - started_s_ - p.start_s;
    holding_ = holding_ && !arrived_;
  }
  if (arrived_ || schedule_s(t_s) < p.measure_s) return;
  // The settle time is over and the table is not there yet: the clock waits at the window's
  // start (no reading of a table on its way counts).
  holding_ = true;
  waited_s_ = t_s - started_s_ - p.measure_s;
}

void AcceptanceRunner::measure(const AcceptancePoint& p, double t_s,
                               const TableObservation& table) {
  if (!stats_.first_s) stats_.first_s = t_s;
  stats_.last_s = t_s;
  if (step_->kind == StepKind::power_cycles) return;
  const bool ladder = step_->kind == StepKind::rate_ladder;
  const std::optional<double> value = ladder ? table.rate_dps : table.angle_deg;
  if (!value) {
    stats_.all_in_position = false;  // an unanswered reading is not a held one
    return;
  }
  const double dev =
      ladder ? std::abs(*value - p.demand) : std::abs(std::remainder(*value - p.demand, 360.0));
  ++stats_.readings;
  stats_.sum += ladder ? *value : p.demand + std::remainder(*value - p.demand, 360.0);
  if (dev > stats_.max_dev) stats_.max_dev = dev;
  if (!ladder && !table.in_position) stats_.all_in_position = false;
}

void AcceptanceRunner::close(const AcceptancePoint& p, AcceptanceActions& a) {
  const double window_s = p.end_s - p.measure_s;
  const bool spanned = stats_.first_s && stats_.last_s &&
                       *stats_.last_s - *stats_.first_s >= window_s - kWindowEdgeS;
  const bool power = step_->kind == StepKind::power_cycles;
  const double tolerance =
      step_->kind == StepKind::rate_ladder ? step_->rate_tolerance_dps : kAngleToleranceDeg;
  const bool held =
      spanned && !cut_ && !unreached_ &&
      (power || (stats_.readings > 0 && stats_.all_in_position && stats_.max_dev <= tolerance));
  nlohmann::json data{{"step_index", step_index_},
                      {"point", p.index},
                      {"demand", p.demand},
                      {"measure_s", started_s_ + waited_s_ + p.measure_s},
                      {"end_s", started_s_ + waited_s_ + p.end_s},
                      {"readings", stats_.readings},
                      {"table_mean", nullptr},
                      {"table_max_dev", nullptr},
                      {"held", held}};
  if (!power && stats_.readings > 0) {
    data["table_mean"] = stats_.sum / stats_.readings;
    data["table_max_dev"] = stats_.max_dev;
  }
  const char* what = step_->kind == StepKind::rate_ladder ? "rate" : power ? "turn-on" : "angle";
  a.events.push_back(
      {held ? Severity::info : Severity::warn, EventKind::acceptance_point,
       held ? (power ? fmt::format("{} {:g} measured", what, p.demand)
                     : fmt::format("{} {:g} measured ({} table readings)", what, p.demand,
                                   stats_.readings))
       : unreached_
           ? fmt::format("{} {:g} not reached: the table was not in position {:g} s after its "
                         "demand: left out",
                         what, p.demand, kPositionMoveDeadlineS)
       : !spanned || cut_
           ? fmt::format("{} {:g} measured over part of its window only (a stop, a kill or a "
                         "safe hold): left out",
                         what, p.demand)
           : fmt::format("{} {:g} not held over its window ({} readings, largest deviation "
                         "{:g}): left out",
                         what, p.demand, stats_.readings, stats_.max_dev),
       std::move(data)});
  stats_ = {};
  cut_ = false;
}

void AcceptanceRunner::rest(AcceptanceActions& a) {
  if (step_->kind == StepKind::rate_ladder)
    a.table = dr::TurntableCommand{dr::TurntableMode::rate, std::nullopt, 0.0, std::nullopt};
  if (step_->kind == StepKind::power_cycles) {
    power_on_ = true;
    a.gyro_power = true;
  }
  rested_ = true;
}

AcceptanceActions AcceptanceRunner::tick(double t_s, const TableObservation& table) {
  AcceptanceActions a;
  if (step_ == nullptr) return a;
  if (current_ >= 0) wait_for_table(points_[static_cast<std::size_t>(current_)], t_s, table);
  double in_s = schedule_s(t_s);
  int now = -1;
  for (const auto& p : points_) {
    if (in_s < p.end_s) {
      now = p.index;
      break;
    }
  }
  if (now != current_ && current_ >= 0) close(points_[static_cast<std::size_t>(current_)], a);
  if (now < 0) {
    if (!rested_ || resend_) rest(a);
    current_ = -1;
    resend_ = false;
    return a;
  }
  const auto& p = points_[static_cast<std::size_t>(now)];
  const bool power_edge =
      step_->kind == StepKind::power_cycles && power_on_ != (in_s >= p.measure_s);
  if (now != current_ || resend_ || power_edge) send(p, t_s, a);
  current_ = now;
  resend_ = false;
  // A new point's move (a resumed run's point met past its settle time and its table not there
  // is measured whole from the table's arrival).
  wait_for_table(p, t_s, table);
  in_s = schedule_s(t_s);
  if (in_s >= p.measure_s && !holding_) measure(p, t_s, table);
  return a;
}

bool AcceptanceRunner::finished(double t_s) const {
  return step_ != nullptr && rested_ && schedule_s(t_s) >= duration_s_;
}

}  // namespace station
