// Safety layer: clamping and the interlock / e-stop safe hold.
#include "station/daemon/safety.hpp"

#include <fmt/format.h>

#include <algorithm>

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

std::optional<std::string> Safety::update(bool interlock_open, bool estop_pressed) {
  const bool was = holding_;
  const bool changed = interlock_open != interlock_open_ || estop_pressed != estop_;
  interlock_open_ = interlock_open;
  estop_ = estop_pressed;
  holding_ = interlock_open_ || estop_;
  if (!changed) return std::nullopt;
  const std::string why =
      fmt::format("interlock {}, e-stop {}", interlock_open_ ? "open" : "closed",
                  estop_ ? "pressed" : "released");
  if (holding_ && !was) return "enter: " + why;
  if (!holding_ && was) return "clear: " + why;
  return "still holding: " + why;
}

drivers::ChamberCommand Safety::hold_command(double air_c) const {
  std::vector<std::string> ignored;
  return clamp(drivers::ChamberCommand{air_c, limits_.max_ramp_c_per_min, true}, ignored);
}

}  // namespace station
