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
  std::vector<std::string> faults;
  if (auto c = rig_.chamber->read(); c) {
    r.chamber = c.value();
    if (r.chamber->alarms.any()) faults.push_back("chamber alarm");
  } else {
    r.io_errors.push_back({"chamber", dr::to_string(c.error().kind)});
    faults.push_back(fmt::format("chamber: {}", c.error().message));
  }
  if (rig_.turntable) {
    if (auto t = rig_.turntable->read(); t) {
      r.table = t.value();
      if (r.table->fault) faults.push_back("turntable drive fault");
    } else {
      r.io_errors.push_back({"turntable", dr::to_string(t.error().kind)});
      faults.push_back(fmt::format("turntable: {}", t.error().message));
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
        faults.push_back(fmt::format("gpio {}: {}", role, v.error().message));
      }
    };
    level(dr::gpio::roles::interlock, r.door_closed);
    level(dr::gpio::roles::estop, r.estop_pressed);
    if (r.estop_pressed.value_or(false)) faults.push_back("e-stop pressed");
    if (r.door_closed && !*r.door_closed) faults.push_back("door open");
  }
  r.fault = fmt::format("{}", fmt::join(faults, "; "));
  if (r.fault != last_fault_) {
    const bool cleared = r.fault.empty();
    const std::string message = cleared ? fmt::format("idle rig clear (was: {})", last_fault_)
                                        : fmt::format("idle rig: {}", r.fault);
    log("serve")->log(cleared ? spdlog::level::info : spdlog::level::warn, "{}", message);
    store_.add_event(std::nullopt, 0, cleared ? "info" : "warn", "serve",
                     cleared ? "idle_clear" : "idle_fault", message);
    last_fault_ = r.fault;
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
