// Idle watch: one read of each device, lamps, and an event per change of the fault.
#include "station/daemon/idle_watch.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "station/common/logging.hpp"

namespace station {

namespace dr = station::drivers;

IdleReading IdleWatch::look() {
  IdleReading r;
  // Edges are for runs; idle reads the levels. No SYNC: the counter boards are latched by runs.
  r.in = read_rig(rig_, RigReadPlan{std::nullopt});
  std::vector<std::string> keys, faults;
  for (auto& f : rig_faults(r.in)) {
    keys.push_back(std::move(f.key));
    faults.push_back(std::move(f.message));
  }
  r.fault = fmt::format("{}", fmt::join(faults, "; "));
  r.fault_key = fmt::format("{}", fmt::join(keys, "; "));
  if (r.fault_key != last_key_) note_change(r);
  (void)outputs_.write(idle_outputs(!r.fault.empty()));  // a failed write: again next look
  return r;
}

void IdleWatch::note_change(IdleReading& r) {
  const bool cleared = r.fault_key.empty();
  const std::string message = cleared ? fmt::format("idle rig clear (was: {})", last_key_)
                                      : fmt::format("idle rig: {}", r.fault);
  log("serve")->log(cleared ? spdlog::level::info : spdlog::level::warn, "{}", message);
  const Severity severity = cleared ? Severity::info : Severity::warn;
  const EventKind kind = cleared ? EventKind::idle_clear : EventKind::idle_fault;
  const nlohmann::json data =
      cleared ? nlohmann::json{{"was", last_key_}} : nlohmann::json{{"fault", r.fault_key}};
  try {
    const auto id = store_.add_event(std::nullopt, 0, severity, "serve", kind, message, data);
    if (on_event_) on_event_({id, 0, 0, severity, "serve", kind, message, data});
    last_key_ = r.fault_key;
    r.storage_error.clear();
  } catch (const SqliteError& e) {
    // The store cannot write (disk full): reported with the reading, the event is tried again
    // at the next look (last_key_ unchanged). Watching the rig never stops for it.
    r.storage_error = e.what();
  }
}

}  // namespace station
