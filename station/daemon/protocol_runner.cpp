// Protocol state machine: entry actions, completion tests and timeouts of each step kind.
#include "station/daemon/protocol_runner.hpp"

#include <fmt/format.h>

#include <cmath>

namespace station {

ProtocolRunner::ProtocolRunner(const Protocol& protocol, const RunProgress& progress)
    : protocol_(protocol), progress_(progress) {
  // The setpoint in force is the last one commanded before the current step.
  setpoint_c_ = previous_target();
}

std::optional<double> ProtocolRunner::previous_target() const {
  std::optional<double> t;
  for (int i = 0; i < progress_.step_index && i < static_cast<int>(protocol_.steps.size()); ++i) {
    if (protocol_.steps[i].kind == StepKind::set_temperature) t = target_of(protocol_.steps[i]);
  }
  return t;
}

double ProtocolRunner::target_of(const Step& s) const {
  if (s.to_start) return progress_.start_temp_c.value_or(25.0);
  return s.setpoint_c.value_or(25.0);
}

void ProtocolRunner::enter(const Step& s, const Observation& obs, Actions& a) {
  entered_ = true;
  stable_since_s_.reset();
  a.events.push_back(
      {Severity::info,
       EventKind::step_start,
       fmt::format("step {} '{}' (line {})", progress_.step_index, s.label, s.line),
       {{"step_index", progress_.step_index}, {"label", s.label}, {"line", s.line}}});
  switch (s.kind) {
    case StepKind::set_temperature:
      ramp_origin_c_ =
          previous_target().value_or(progress_.start_temp_c.value_or(obs.air_c.value_or(25.0)));
      if (resume_from_c_ && s.ramp_c_per_h > 0) {
        // Back from a safe hold: the ramp goes on at its rate from where the chamber was held.
        ramp_origin_c_ = *resume_from_c_;
        progress_.step_started_s = obs.t_s;
        a.events.push_back({Severity::info,
                            EventKind::ramp_resume,
                            fmt::format("ramp resumes from {:.2f} C at {:.1f} C/h", ramp_origin_c_,
                                        s.ramp_c_per_h),
                            {{"from_c", ramp_origin_c_}, {"ramp_c_per_h", s.ramp_c_per_h}}});
      }
      setpoint_c_ = target_of(s);
      ramp_sent_c_.reset();
      if (s.ramp_c_per_h <= 0) a.chamber = drivers::ChamberCommand{setpoint_c_, 0.0, true};
      break;
    case StepKind::lock_turntable:
      if (obs.has_turntable) {
        // Release and move first; lock_table() locks once a later reading shows it there.
        a.table = drivers::TurntableCommand{drivers::TurntableMode::position, s.position_deg,
                                            std::nullopt, false};
      }
      move_sent_s_ = obs.t_s;
      lock_sent_s_.reset();
      break;
    case StepKind::record_start:
      progress_.recording = true;
      progress_.record_start_s = obs.t_s;
      a.events.push_back({Severity::info, EventKind::record_start,
                          fmt::format("record window opens at {:.0f} s", obs.t_s)});
      break;
    case StepKind::record_stop:
      progress_.recording = false;
      a.events.push_back({Severity::info, EventKind::record_stop,
                          fmt::format("record window closes at {:.0f} s", obs.t_s)});
      break;
    case StepKind::rate_ladder:
    case StepKind::positions:
    case StepKind::power_cycles:
      acceptance_.enter(s, progress_.step_index, progress_.step_started_s);
      break;
    default:
      break;
  }
  resume_from_c_.reset();
}

bool ProtocolRunner::table_at(const Step& s, const Observation& obs) {
  constexpr double kAngleTolerance_deg = 0.1;
  return obs.table_in_position.value_or(false) && obs.table_angle_deg &&
         std::abs(std::remainder(*obs.table_angle_deg - s.position_deg, 360.0)) <=
             kAngleTolerance_deg;
}

void ProtocolRunner::lock_table(const Step& s, const Observation& obs, Actions& a) {
  if (!obs.has_turntable || lock_sent_s_ || !move_sent_s_ || obs.t_s <= *move_sent_s_) return;
  if (!table_at(s, obs)) return;
  a.table =
      drivers::TurntableCommand{drivers::TurntableMode::position, std::nullopt, std::nullopt, true};
  lock_sent_s_ = obs.t_s;
}

void ProtocolRunner::ramp(const Step& s, const Observation& obs, Actions& a) {
  const double span_c = *setpoint_c_ - ramp_origin_c_;
  const double moved_c = s.ramp_c_per_h * (obs.t_s - progress_.step_started_s) / 3600.0;
  const double sp =
      std::abs(span_c) <= moved_c ? *setpoint_c_ : ramp_origin_c_ + std::copysign(moved_c, span_c);
  if (ramp_sent_c_ && std::abs(sp - *ramp_sent_c_) < 0.05 && sp != *setpoint_c_) return;
  if (ramp_sent_c_ && *ramp_sent_c_ == sp) return;
  // The first command of a ramp sets the controller to a step (bounded by the safety layer) and
  // enables it; the later ones only move the setpoint.
  a.chamber = ramp_sent_c_ ? drivers::ChamberCommand{sp, std::nullopt, std::nullopt}
                           : drivers::ChamberCommand{sp, 0.0, true};
  ramp_sent_c_ = sp;
}

bool ProtocolRunner::in_acceptance_step() const {
  return !done() &&
         is_acceptance_step(protocol_.steps[static_cast<std::size_t>(progress_.step_index)].kind);
}

void ProtocolRunner::merge(AcceptanceActions acts, Actions& a) {
  if (acts.table) a.table = acts.table;
  if (acts.gyro_power) a.gyro_power = acts.gyro_power;
  for (auto& e : acts.events) a.events.push_back(std::move(e));
}

void ProtocolRunner::accept(const Observation& obs, Actions& a) {
  merge(acceptance_.tick(obs.t_s, {obs.table_rate_dps, obs.table_angle_deg,
                                   obs.table_in_position.value_or(false)}),
        a);
}

bool ProtocolRunner::finished(const Step& s, const Observation& obs) {
  const double in_step_s = obs.t_s - progress_.step_started_s;
  switch (s.kind) {
    case StepKind::set_temperature:
      if (s.ramp_c_per_h > 0 && ramp_sent_c_ != setpoint_c_) return false;
      return !s.wait || (obs.air_c && std::abs(*obs.air_c - *setpoint_c_) <= s.tolerance_c);
    case StepKind::soak: {
      const double sp = setpoint_c_.value_or(obs.air_c.value_or(25.0));
      bool stable =
          obs.air_c && std::abs(*obs.air_c - sp) <= s.tolerance_c && !obs.gyro_temps_c.empty();
      for (double g : obs.gyro_temps_c) stable = stable && std::abs(g - sp) <= s.tolerance_c;
      if (!stable) {
        stable_since_s_.reset();
        return false;
      }
      if (!stable_since_s_) stable_since_s_ = obs.t_s;
      return obs.t_s - *stable_since_s_ >= s.duration_s;
    }
    case StepKind::hold:
      return in_step_s >= s.duration_s;
    case StepKind::rate_ladder:
    case StepKind::positions:
    case StepKind::power_cycles:
      return acceptance_.finished(obs.t_s);
    case StepKind::lock_turntable:
      // Done on a reading taken after the lock command that shows the table there and locked.
      return !obs.has_turntable || (lock_sent_s_ && obs.t_s > *lock_sent_s_ && table_at(s, obs) &&
                                    obs.table_locked.value_or(false));
    default:
      return true;
  }
}

void ProtocolRunner::advance(const Observation& obs, Actions& a, EventKind kind, Severity sev) {
  const Step& s = protocol_.steps[static_cast<std::size_t>(progress_.step_index)];
  const double after_s = obs.t_s - progress_.step_started_s;
  a.events.push_back(
      {sev,
       kind,
       fmt::format("step {} '{}' {} after {:.0f} s", progress_.step_index, s.label,
                   kind == EventKind::step_timeout ? "timed out" : "done", after_s),
       {{"step_index", progress_.step_index}, {"label", s.label}, {"after_s", after_s}}});
  ++progress_.step_index;
  progress_.step_started_s = obs.t_s;
  entered_ = false;
}

Actions ProtocolRunner::tick(const Observation& obs) {
  Actions a;
  if (!progress_.start_temp_c && obs.air_c) progress_.start_temp_c = obs.air_c;
  // Instant steps (record_start/stop, set_temperature without wait) chain within one tick.
  for (int guard = 0; guard < 64 && !done(); ++guard) {
    const Step& s = protocol_.steps[static_cast<std::size_t>(progress_.step_index)];
    if (!entered_) enter(s, obs, a);
    if (s.kind == StepKind::set_temperature && s.ramp_c_per_h > 0) ramp(s, obs, a);
    if (s.kind == StepKind::lock_turntable) lock_table(s, obs, a);
    if (is_acceptance_step(s.kind)) accept(obs, a);
    if (finished(s, obs)) {
      advance(obs, a, EventKind::step_done, Severity::info);
      continue;
    }
    if (s.timeout_s > 0 && obs.t_s - progress_.step_started_s > s.timeout_s) {
      if (is_acceptance_step(s.kind)) merge(acceptance_.leave(), a);
      advance(obs, a, EventKind::step_timeout, Severity::warn);
      continue;
    }
    break;
  }
  if (done() && !a.events.empty() && a.events.back().kind != EventKind::done) {
    a.events.push_back(
        {Severity::info, EventKind::done, fmt::format("protocol '{}' complete", protocol_.name)});
  }
  return a;
}

}  // namespace station
