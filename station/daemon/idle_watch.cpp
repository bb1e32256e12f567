// Idle watch: one read of each device, lamps, and an event per change of the fault.
#include "station/daemon/idle_watch.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drivers/gpio/gpio_bank.hpp"
#include "station/common/logging.hpp"

namespace station {

namespace dr = station::drivers;

IdleReading IdleWatch::look() {
  IdleReading r;
  // Each fault as a stable key and a message: a link's message carries its reconnect countdown,
  // which changes every second; an event is stored when the keys change, not the words.
  std::vector<std::string> keys, faults;
  const auto fault = [&](std::string key, std::string message) {
    keys.push_back(std::move(key));
    faults.push_back(std::move(message));
  };
  if (auto c = rig_.chamber->read(); c) {
    r.chamber = c.value();
    if (r.chamber->alarms.any()) fault("chamber alarm", "chamber alarm");
  } else {
    r.io_errors.push_back({"chamber", dr::to_string(c.error().kind)});
    fault(fmt::format("chamber {}", dr::to_string(c.error().kind)), c.error().message);
  }
  if (rig_.turntable) {
    if (auto t = rig_.turntable->read(); t) {
      r.table = t.value();
      if (r.table->fault) fault("turntable fault", "turntable drive fault");
      // An e-stop chain that cuts the drive's enable shows here (docs/SIMRIG.md).
      if (r.table->interlock_open) fault("turntable interlock", "turntable interlock open");
    } else {
      r.io_errors.push_back({"turntable", dr::to_string(t.error().kind)});
      fault(fmt::format("turntable {}", dr::to_string(t.error().kind)), t.error().message);
    }
  }
  if (rig_.gpio) {
    (void)rig_.gpio->read_events();  // edges are for runs; idle reads the levels
    const auto level = [&](std::string_view role, std::optional<bool>& out) {
      if (dr::gpio::find_role(rig_.gpio->config(), role) == nullptr) return;
      if (auto v = rig_.gpio->read(role); v) {
        out = v.value();
      } else {
        r.io_errors.push_back({"gpio", dr::to_string(v.error().kind)});
        fault(fmt::format("gpio {} {}", role, dr::to_string(v.error().kind)), v.error().message);
      }
    };
    level(dr::gpio::roles::interlock, r.door_closed);
    level(dr::gpio::roles::estop, r.estop_pressed);
    if (r.estop_pressed.value_or(false)) fault("e-stop", "e-stop pressed");
    if (r.door_closed && !*r.door_closed) fault("door", "door open");
  }
  r.fault = fmt::format("{}", fmt::join(faults, "; "));
  r.fault_key = fmt::format("{}", fmt::join(keys, "; "));
  if (r.fault_key != last_key_) {
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
  drive_lamps(!r.fault.empty());
  return r;
}

void IdleWatch::drive_lamps(bool red) {
  if (!rig_.gpio || (lamps_written_ && red == red_)) return;
  bool ok = true;
  const auto set = [&](std::string_view role, bool on) {
    if (dr::gpio::find_role(rig_.gpio->config(), role) == nullptr) return;
    ok = rig_.gpio->write(role, on).ok() && ok;
  };
  set(dr::gpio::roles::tower_green, false);
  set(dr::gpio::roles::tower_amber, !red);  // amber: idle, ready for a run
  set(dr::gpio::roles::tower_red, red);
  lamps_written_ = ok;  // a failed write is tried again at the next look
  red_ = red;
}

}  // namespace station
