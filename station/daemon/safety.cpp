// Safety layer: clamping, judging device readings against the limits, and the safe hold.
#include "station/daemon/safety.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

namespace station {

drivers::ChamberCommand Safety::clamp(drivers::ChamberCommand cmd,
                                      std::vector<std::string>& notes) const {
  if (cmd.setpoint_c) {
    const double v = std::clamp(*cmd.setpoint_c, limits_.min_setpoint_c, limits_.max_setpoint_c);
    if (v != *cmd.setpoint_c) {
      notes.push_back(fmt::format("setpoint {:.2f} C clamped to {:.2f} C (limits {:.1f}..{:.1f} C)",
                                  *cmd.setpoint_c, v, limits_.min_setpoint_c,
                                  limits_.max_setpoint_c));
      cmd.setpoint_c = v;
    }
  }
  if (cmd.ramp_c_per_min) {
    // A step (0) is an unbounded rate: the controller is always given the station's maximum
    // instead. That is the normal way to bound a step, not a clamp of what the protocol asked.
    const double asked = *cmd.ramp_c_per_min;
    const double v =
        asked <= 0 ? limits_.max_ramp_c_per_min : std::min(asked, limits_.max_ramp_c_per_min);
    if (asked > 0 && v != asked) {
      notes.push_back(fmt::format("ramp {:.3f} C/min clamped to {:.3f} C/min (limit {:.3f})", asked,
                                  v, limits_.max_ramp_c_per_min));
    }
    cmd.ramp_c_per_min = v;  // a step too (found by the issue-20 review: it stayed 0)
  }
  return cmd;
}

Protocol Safety::clamp_protocol(const Protocol& p, std::vector<std::string>& notes,
                                bool controller_ramp) const {
  Protocol out = p;
  const double max_ramp_c_per_h = 60.0 * limits_.max_ramp_c_per_min;
  for (std::size_t i = 0; i < out.steps.size(); ++i) {
    Step& s = out.steps[i];
    const auto where = fmt::format("{}:{}: step {} '{}'", p.path, s.line, i, s.label);
    if (s.setpoint_c) {
      const double v = std::clamp(*s.setpoint_c, limits_.min_setpoint_c, limits_.max_setpoint_c);
      if (v != *s.setpoint_c) {
        notes.push_back(fmt::format(
            "{}: setpoint {:.2f} C clamped to {:.2f} C (station limits {:.1f}..{:.1f} C)", where,
            *s.setpoint_c, v, limits_.min_setpoint_c, limits_.max_setpoint_c));
        s.setpoint_c = v;
      }
    }
    if (!controller_ramp && s.kind == StepKind::set_temperature && s.ramp_c_per_h <= 0) {
      // Named by protocol line, not file: a replay reads the protocol from another path.
      notes.push_back(
          fmt::format("step {} '{}' (line {}): ramped by the station at {:.1f} C/h "
                      "(the chamber has no ramp of its own)",
                      i, s.label, s.line, max_ramp_c_per_h));
      s.ramp_c_per_h = max_ramp_c_per_h;
    }
    if (s.ramp_c_per_h > max_ramp_c_per_h) {
      notes.push_back(fmt::format("{}: ramp {:.1f} C/h clamped to {:.1f} C/h (station limit)",
                                  where, s.ramp_c_per_h, max_ramp_c_per_h));
      s.ramp_c_per_h = max_ramp_c_per_h;
    }
  }
  return out;
}

SafetyInputs safety_inputs(const RigReading& in, std::optional<double> air_c) {
  std::optional<bool> drive_fault;
  if (in.table) drive_fault = in.table->fault;
  return {in.chamber,     in.table_interlock_open, drive_fault,
          in.door_closed, in.estop_pressed,        air_c};
}

std::vector<std::string> Safety::judge(const std::optional<drivers::ChamberState>& chamber) const {
  std::vector<std::string> out;
  if (!chamber) return out;
  const double lo = limits_.min_setpoint_c, hi = limits_.max_setpoint_c;
  const double sp = chamber->setpoint_c, air = chamber->air_c;
  // A NaN read-back fails both comparisons below: treat it as out of limits too.
  if (!(sp >= lo && sp <= hi)) {
    out.push_back(fmt::format("chamber setpoint read back {:.2f} C outside limits {:.1f}..{:.1f} C",
                              sp, lo, hi));
  }
  // A NaN air temperature is a sensor break, reported by the chamber's alarms, not judged here.
  const double m = limits_.air_margin_c;
  if (std::isfinite(air) && (air < lo - m || air > hi + m)) {
    out.push_back(
        fmt::format("chamber air {:.2f} C beyond limits {:.1f}..{:.1f} C by more than "
                    "{:.1f} C",
                    air, lo, hi, m));
  }
  return out;
}

namespace {

/// Each cause's name while it is on and once it clears, in the order events list them.
struct CauseWords {
  bool SafetyCauses::*flag;
  const char* on;
  const char* cleared;
};
constexpr CauseWords kCauseWords[] = {
    {&SafetyCauses::chamber_high_limit, "chamber high-limit trip", "chamber high-limit trip reset"},
    {&SafetyCauses::chamber_sensor_break, "chamber air sensor break",
     "chamber air sensor reads again"},
    {&SafetyCauses::chamber_air_implausible, "chamber air reading implausible",
     "chamber air reads plausibly again"},
    {&SafetyCauses::setpoint_foreign, "chamber setpoint written by another master",
     "chamber setpoint reads the station's again"},
    {&SafetyCauses::estop_pressed, "e-stop pressed", "e-stop released"},
    {&SafetyCauses::chamber_door_open, "chamber door open", "chamber door closed"},
    {&SafetyCauses::door_open, "interlock open", "interlock closed"},
    {&SafetyCauses::table_interlock_open, "turntable interlock open", "turntable interlock closed"},
    {&SafetyCauses::table_drive_fault, "turntable drive fault", "turntable drive fault cleared"},
    {&SafetyCauses::inputs_unreadable, "interlock / e-stop unreadable",
     "interlock / e-stop readable again"},
};

std::string words_of(const SafetyCauses& c, bool cleared) {
  std::vector<std::string> words;
  for (const auto& w : kCauseWords)
    if (c.*w.flag) words.emplace_back(cleared ? w.cleared : w.on);
  if (!c.out_of_limits.empty()) {
    words.push_back(cleared ? std::string("readings back inside limits")
                            : fmt::format("out of limits: {}", fmt::join(c.out_of_limits, "; ")));
  }
  return words.empty() ? std::string("no cause") : fmt::format("{}", fmt::join(words, "; "));
}

}  // namespace

std::string SafetyCauses::text() const {
  return words_of(*this, false);
}

std::string SafetyCauses::cleared_text() const {
  return words_of(*this, true);
}

std::optional<std::string> Safety::update(SafetyCauses causes) {
  const bool was = holding_;
  const bool changed = !(causes == causes_);
  const SafetyCauses before = causes_;
  causes_ = std::move(causes);
  limits_fault_ = !causes_.out_of_limits.empty();
  holding_ = causes_.any();
  if (!changed) return std::nullopt;
  if (holding_ && !was) return "enter: " + causes_.text();
  if (!holding_ && was) return "clear: " + before.cleared_text() + "; every cause reads clear";
  return "still holding: " + causes_.text();
}

bool Safety::blind(const SafetyInputs& in) const {
  return (sources_.table && !in.table_interlock_open) ||
         (sources_.gpio_interlock && !in.door_closed) || (sources_.gpio_estop && !in.estop_pressed);
}

SafetyDecision Safety::decide(const SafetyInputs& in) {
  SafetyDecision d;
  blind_ticks_ = blind(in) ? blind_ticks_ + 1 : 0;
  if (blind_ticks_ == kBlindTicks) {
    d.events.push_back(
        {Severity::error, EventKind::inputs_unreadable,
         fmt::format("interlock / e-stop unreadable for {} ticks: treated as open", kBlindTicks)});
  }
  // Each input is judged from its own reading; one that could not be read keeps its own last
  // known state (an unconfigured one is never a cause). The chamber's door switch counts as an
  // interlock, its high-limit trip as an e-stop.
  SafetyCauses c = causes_;
  if (in.table_interlock_open) c.table_interlock_open = *in.table_interlock_open;
  // A drive fault: the drive is disabled and the table coasts, so no rate or position demand is
  // held; the hold stops the run's steps until someone clears the fault at the drive.
  if (in.table_drive_fault) c.table_drive_fault = *in.table_drive_fault;
  if (in.door_closed) c.door_open = !*in.door_closed;
  if (in.estop_pressed) c.estop_pressed = *in.estop_pressed;
  if (in.chamber) {
    c.chamber_door_open = in.chamber->alarms.door_open;
    c.chamber_high_limit = in.chamber->alarms.high_limit_trip;
    c.chamber_sensor_break = in.chamber->alarms.sensor_break;
    c.out_of_limits = judge(in.chamber);
    alarm_events(in.chamber->alarms, d.events);
    // An implausible air holds once it lasts as long as an unreadable interlock may.
    implausible_ticks_ = in.air_implausible ? implausible_ticks_ + 1 : 0;
  }
  c.chamber_air_implausible = implausible_ticks_ >= kBlindTicks;
  c.setpoint_foreign = in.setpoint_foreign;
  c.inputs_unreadable = blind_ticks_ >= kBlindTicks;
  if (c.chamber_sensor_break != causes_.chamber_sensor_break)
    d.events.push_back(sensor_event(c.chamber_sensor_break));
  // No air to hold at (nor to resume a ramp from) that a hold's cause made untrustworthy: a
  // broken sensor's, an implausible one, air beyond the limits; nor a hold setpoint written over
  // another master's until the operator answers it.
  const double lo = limits_.min_setpoint_c - limits_.air_margin_c;
  const double hi = limits_.max_setpoint_c + limits_.air_margin_c;
  const bool untrusted = c.chamber_sensor_break || in.air_implausible || c.setpoint_foreign ||
                         (in.air_c && !(*in.air_c >= lo && *in.air_c <= hi));
  const auto air_c = untrusted ? std::nullopt : in.air_c;
  const bool was = holding_;
  const auto change = update(std::move(c));
  finish(d, was, change, in.chamber, air_c);
  return d;
}

SafetyEvent Safety::sensor_event(bool broken) {
  const nlohmann::json data{{"device", "chamber"}, {"sensor", "air"}};
  if (broken)
    return {Severity::error, EventKind::sensor_fault,
            "chamber air sensor break: no air reading (samples keep air empty); held until it "
            "reads again",
            data};
  return {Severity::info, EventKind::sensor_fault_cleared, "chamber air sensor reads again", data};
}

void Safety::alarm_events(const drivers::AlarmBits& now, std::vector<SafetyEvent>& events) {
  struct Alarm {
    bool drivers::AlarmBits::*flag;
    const char* name;
    Severity severity;  ///< while on: error for the ones that hold a run
  };
  static constexpr Alarm kAlarms[] = {
      {&drivers::AlarmBits::high_limit_trip, "high_limit_trip", Severity::error},
      {&drivers::AlarmBits::door_open, "door_open", Severity::error},
      {&drivers::AlarmBits::deviation, "deviation", Severity::warn},
      {&drivers::AlarmBits::other, "other", Severity::warn},
  };
  for (const auto& a : kAlarms) {
    if (now.*a.flag == alarms_.*a.flag) continue;
    const nlohmann::json data{{"alarm", a.name}};
    if (now.*a.flag)
      events.push_back({a.severity, EventKind::chamber_alarm,
                        fmt::format("chamber alarm on: {}", a.name), data});
    else
      events.push_back({Severity::info, EventKind::chamber_alarm_cleared,
                        fmt::format("chamber alarm off: {}", a.name), data});
  }
  alarms_ = now;
}

SafetyDecision Safety::decide_between_ticks(std::optional<bool> door_closed,
                                            std::optional<bool> estop_pressed,
                                            std::optional<double> air_c) {
  SafetyDecision d;
  const bool open = door_closed && !*door_closed;
  const bool pressed = estop_pressed.value_or(false);
  if (holding_ || !(open || pressed)) {
    d.holding = holding_;
    d.outputs = outputs();
    return d;
  }
  // An edge only adds a cause; readings out of limits are judged at the ticks.
  SafetyCauses c = causes_;
  c.door_open = c.door_open || open;
  c.estop_pressed = c.estop_pressed || pressed;
  const bool was = holding_;
  auto change = update(std::move(c));
  if (change) *change += " (between ticks)";
  finish(d, was, change, std::nullopt, air_c);
  return d;
}

void Safety::finish(SafetyDecision& d, bool was, const std::optional<std::string>& change,
                    const std::optional<drivers::ChamberState>& chamber,
                    std::optional<double> air_c) {
  d.holding = holding_;
  if (change && holding_ && !was) {
    d.entered = true;
    d.events.push_back({Severity::error, EventKind::safe_hold,
                        *change + ": chamber held at its air temperature, turntable stopped"});
    hold_air_c_ = air_c;
    hold_acknowledged_ = false;
    table_stopped_ = !sources_.table;
  } else if (change && holding_) {
    d.events.push_back({Severity::error, EventKind::safe_hold_changed, *change});
  } else if (change && was) {
    d.cleared = true;
    // A hold that never had a trustworthy air reading (a sensor break) resumes from this one.
    d.hold_air_c = hold_air_c_ ? hold_air_c_ : air_c;
    d.events.push_back(
        {Severity::info, EventKind::safe_hold_cleared, *change + ": resuming the protocol step"});
  }
  if (holding_) {
    // The hold setpoint needs one air reading; it is retried every tick until accepted.
    if (!hold_air_c_) hold_air_c_ = air_c;
    d.hold_air_c = hold_air_c_;
    // Someone else wrote the setpoint during the hold: the hold is written again.
    if (chamber && !(chamber->setpoint_c >= limits_.min_setpoint_c &&
                     chamber->setpoint_c <= limits_.max_setpoint_c))
      hold_acknowledged_ = false;
    if (!hold_acknowledged_ && hold_air_c_) d.chamber = hold_command(*hold_air_c_);
    d.stop_table = !table_stopped_;
  }
  d.outputs = outputs();
}

void Safety::acknowledge(bool chamber_hold_ok, bool table_stop_ok) {
  hold_acknowledged_ = hold_acknowledged_ || chamber_hold_ok;
  table_stopped_ = table_stopped_ || table_stop_ok;
}

SafetyOutputs idle_outputs(bool fault) {
  SafetyOutputs o;
  o.red = fault;
  o.amber = !fault;  // amber: idle, ready for a run
  return o;
}

SafetyOutputs Safety::outputs() const {
  SafetyOutputs o;
  // Red: a fault (e-stop, readings out of limits, a broken sensor, a faulted drive); amber: safe
  // hold; green: running. The gyros are powered while the run goes on and cut in every safe hold
  // (the RLG's discharge supply is high voltage; a hold is when a person may reach into the
  // chamber).
  o.red = limits_fault_ || causes_.estop() || causes_.device_fault();
  o.amber = holding_ && !o.red;
  o.green = !holding_;
  o.gyro_power = !holding_;
  return o;
}

drivers::ChamberCommand Safety::hold_command(double air_c) const {
  std::vector<std::string> ignored;
  return clamp(drivers::ChamberCommand{air_c, limits_.max_ramp_c_per_min, true}, ignored);
}

}  // namespace station
