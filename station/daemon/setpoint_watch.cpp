// A setpoint the station did not write: detected, reported, restored or held for.
#include "station/daemon/setpoint_watch.hpp"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

namespace station {

std::optional<ForeignSetpoint> parse_foreign_setpoint(std::string_view text) {
  if (text == "restore") return ForeignSetpoint::restore;
  if (text == "hold") return ForeignSetpoint::hold;
  return std::nullopt;
}

const char* to_string(ForeignSetpoint f) {
  return f == ForeignSetpoint::hold ? "hold" : "restore";
}

SetpointNews SetpointWatch::observe(const std::optional<drivers::ChamberState>& chamber,
                                    double resolution_c) {
  SetpointNews news;
  // No reading: no news. A read-back that is no number is the safety layer's (out of limits),
  // not another master's.
  if (!chamber || !std::isfinite(chamber->setpoint_c)) return news;
  // Before the station has commanded one (a new daemon resuming a hold step commands none), the
  // setpoint it finds is the reference: what the chamber holds when the station takes over.
  if (!commanded_c_) commanded_c_ = chamber->setpoint_c;
  const double read_c = chamber->setpoint_c;
  // Within one register step (plus rounding of the scaling) the read-back is what was written.
  const auto within = [&](double c) { return std::abs(read_c - c) <= resolution_c + 1e-6; };
  // A write whose reply was lost reached the chamber after all: the station's own value.
  if (tried_c_ && within(*tried_c_)) commanded_c_ = *tried_c_, tried_c_.reset();
  const double commanded_c = *commanded_c_;
  const bool differs = !within(commanded_c);
  if (differs && !foreign_) {
    foreign_ = true;
    const bool hold = action_ == ForeignSetpoint::hold;
    news.events.push_back(
        {hold ? Severity::error : Severity::warn,
         EventKind::setpoint_foreign,
         fmt::format("chamber setpoint reads {:.2f} C, the station commanded {:.2f} C (the panel "
                     "or another master): {}",
                     read_c, commanded_c,
                     hold ? "the run holds until it reads the station's value again"
                          : "the station's value is written again"),
         {{"read_c", read_c}, {"commanded_c", commanded_c}, {"action", to_string(action_)}}});
  } else if (!differs && foreign_) {
    foreign_ = false;
    news.events.push_back(
        {Severity::info,
         EventKind::setpoint_foreign_end,
         fmt::format("chamber setpoint reads the station's {:.2f} C again", commanded_c),
         {{"read_c", read_c}, {"commanded_c", commanded_c}}});
  }
  if (foreign_ && action_ == ForeignSetpoint::restore) news.restore_c = commanded_c;
  return news;
}

}  // namespace station
