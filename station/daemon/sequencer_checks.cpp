// The sequencer's checks of what the devices report beyond their links (issue 34): readings no
// device could give (plausibility.hpp) and a setpoint the station did not write
// (setpoint_watch.hpp).
#include <fmt/format.h>

#include <chrono>

#include "station/daemon/sequencer.hpp"

namespace station {

void Sequencer::screen(double t_s, TickData& d) {
  const bool chamber_read = d.in.chamber.has_value(), table_read = d.in.table.has_value();
  const auto found = screen_reading(d.in, plausible_ranges(rig_));
  for (const auto& f : found)
    d.air_implausible = d.air_implausible || (f.device == "chamber" && f.quantity == "air_c");
  for (const auto& e : plausibility_.observe(found, chamber_read, table_read))
    emit(t_s, e.data["device"].get<std::string>(), e);
}

void Sequencer::check_setpoint(double t_s, const TickData& d) {
  const auto news = setpoint_watch_.observe(d.in.chamber, rig_.chamber->setpoint_resolution_c());
  for (const auto& e : news.events) emit(t_s, "chamber", e);
  if (!news.restore_c) return;
  // Written again each tick until the read-back shows it (a refusal is retried next tick).
  const drivers::ChamberCommand restore{*news.restore_c, std::nullopt, std::nullopt};
  if (auto r = command_chamber(restore); !r && command_failures_++ % 60 == 0)
    emit(t_s, Severity::warn, "chamber", EventKind::command_failed,
         fmt::format("restoring the setpoint {:.2f} C: {}", *news.restore_c, r.error().message));
}

void Sequencer::note_commanded(const drivers::ChamberCommand& c) {
  if (c.setpoint_c) setpoint_watch_.commanded(*c.setpoint_c);
}

std::optional<drivers::Error> Sequencer::io_spent(const char* what) const {
  if (!io_end_ || std::chrono::steady_clock::now() < *io_end_) return std::nullopt;
  return drivers::make_error(
      drivers::ErrorKind::timeout,
      fmt::format("{} not sent this tick: the tick's device I/O took its {:.2f} s ({:.0f} % of "
                  "the period); retried next tick",
                  what, kTickIoShare * options_.period_s, 100 * kTickIoShare));
}

namespace {

// A write that failed this way may have reached the device: only a refusal (an exception reply)
// or a value refused before sending (range) says it did not.
bool outcome_unknown(drivers::ErrorKind k) {
  return k != drivers::ErrorKind::exception && k != drivers::ErrorKind::range;
}

}  // namespace

drivers::Result<void> Sequencer::command_chamber(const drivers::ChamberCommand& c) {
  if (auto spent = io_spent("chamber command")) return *spent;  // not sent: nothing tried
  if (c.setpoint_c) setpoint_watch_.trying(*c.setpoint_c);
  auto r = rig_.chamber->command(c);
  if (r) note_commanded(c);
  if (!r && c.setpoint_c) setpoint_watch_.failed(outcome_unknown(r.error().kind));
  return r;
}

drivers::Result<void> Sequencer::command_table(const drivers::TurntableCommand& c) {
  if (auto spent = io_spent("turntable command")) return *spent;
  return rig_.turntable->command(c);
}

drivers::Result<void> Sequencer::stop_table() {
  if (auto spent = io_spent("turntable stop")) return *spent;
  return rig_.turntable->stop();
}

void Sequencer::rest_table(double t_s) {
  if (!table_released_ || !rig_.turntable) return;
  if (auto r = stop_table(); !r)
    emit(t_s, Severity::error, "table", EventKind::stop_failed,
         "the run ended with the table released and turning, and the stop failed: " +
             r.error().message);
  table_released_ = false;
}

}  // namespace station
