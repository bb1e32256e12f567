// The sequencer's checks of what the devices report beyond their links (issue 34): readings no
// device could give (plausibility.hpp) and a setpoint the station did not write
// (setpoint_watch.hpp).
#include <fmt/format.h>

#include "station/daemon/sequencer.hpp"

namespace station {

void Sequencer::screen(double t_s, TickData& d) {
  const bool chamber_read = d.in.chamber.has_value(), table_read = d.in.table.has_value();
  const auto found = screen_reading(d.in, plausible_ranges(config_.limits, rig_));
  for (const auto& f : found) d.air_implausible = d.air_implausible || f.device == "chamber";
  for (const auto& e : plausibility_.observe(found, chamber_read, table_read))
    emit(t_s, e.data["device"].get<std::string>(), e);
}

void Sequencer::check_setpoint(double t_s, const TickData& d) {
  const auto news = setpoint_watch_.observe(d.in.chamber, rig_.chamber->setpoint_resolution_c());
  for (const auto& e : news.events) emit(t_s, "chamber", e);
  if (!news.restore_c) return;
  // Written again each tick until the read-back shows it (a refusal is retried next tick).
  const drivers::ChamberCommand restore{*news.restore_c, std::nullopt, std::nullopt};
  if (auto r = rig_.chamber->command(restore); !r && command_failures_++ % 60 == 0)
    emit(t_s, Severity::warn, "chamber", EventKind::command_failed,
         fmt::format("restoring the setpoint {:.2f} C: {}", *news.restore_c, r.error().message));
}

void Sequencer::note_commanded(const drivers::ChamberCommand& c) {
  if (c.setpoint_c) setpoint_watch_.commanded(*c.setpoint_c);
}

}  // namespace station
