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
      cmd.ramp_c_per_min = v;
    }
  }
  return cmd;
}

Protocol Safety::clamp_protocol(const Protocol& p, std::vector<std::string>& notes) const {
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
    if (s.ramp_c_per_h > max_ramp_c_per_h) {
      notes.push_back(fmt::format("{}: ramp {:.1f} C/h clamped to {:.1f} C/h (station limit)",
                                  where, s.ramp_c_per_h, max_ramp_c_per_h));
      s.ramp_c_per_h = max_ramp_c_per_h;
    }
  }
  return out;
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

std::optional<std::string> Safety::update(bool interlock_open, bool estop_pressed,
                                          const std::vector<std::string>& out_of_limits) {
  const bool was = holding_;
  const bool fault = !out_of_limits.empty();
  const bool changed =
      interlock_open != interlock_open_ || estop_pressed != estop_ || fault != limits_fault_;
  interlock_open_ = interlock_open;
  estop_ = estop_pressed;
  limits_fault_ = fault;
  holding_ = interlock_open_ || estop_ || limits_fault_;
  if (!changed) return std::nullopt;
  std::string why = fmt::format("interlock {}, e-stop {}", interlock_open_ ? "open" : "closed",
                                estop_ ? "pressed" : "released");
  why += fault ? fmt::format(", out of limits: {}", fmt::join(out_of_limits, "; "))
               : ", readings inside limits";
  if (holding_ && !was) return "enter: " + why;
  if (!holding_ && was) return "clear: " + why;
  return "still holding: " + why;
}

drivers::ChamberCommand Safety::hold_command(double air_c) const {
  std::vector<std::string> ignored;
  return clamp(drivers::ChamberCommand{air_c, limits_.max_ramp_c_per_min, true}, ignored);
}

}  // namespace station
