// The rig read once, in one order, and judged in one place.
#include "station/daemon/rig_reading.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <string_view>

#include "drivers/common/exchange_deadline.hpp"
#include "station/daemon/stopwatch.hpp"

namespace station {

namespace dr = station::drivers;

namespace {

double* field(RigReadTimes* t, double RigReadTimes::*m) {
  return t == nullptr ? nullptr : &(t->*m);
}

void read_counters(Rig& rig, std::uint8_t seq, RigReading& r) {
  auto counts = rig.counters->tick(seq);
  if (counts) {
    r.counters = std::move(counts).value();
  } else {
    r.io_errors.push_back({"can", dr::to_string(counts.error().kind)});
    r.counters_error = counts.error();
  }
}

// The budget of one reading (RigReadPlan::budget_s) on the steady clock: the exchanges it bounds
// run on the wall, whatever clock the run keeps.
class ReadBudget {
 public:
  explicit ReadBudget(std::optional<double> budget_s) : budget_s_(budget_s) {}
  /// When the budget ends (none: no budget).
  std::optional<std::chrono::steady_clock::time_point> end() const {
    if (!budget_s_) return std::nullopt;
    return start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(*budget_s_));
  }
  /// Why `device` is not read now (its turn came after the budget was spent), or nothing.
  std::optional<dr::Error> spent(std::string_view device) const {
    const double used_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (!budget_s_ || used_s < *budget_s_) return std::nullopt;
    return dr::make_error(dr::ErrorKind::timeout,
                          fmt::format("{} not read this tick: the chamber took {:.2f} s of the "
                                      "tick's {:.2f} s for device exchanges",
                                      device, used_s, *budget_s_));
  }

 private:
  std::optional<double> budget_s_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

void read_devices(Rig& rig, const RigReadPlan& plan, RigReading& r, RigReadTimes* times) {
  const ReadBudget budget(plan.budget_s);  // from the chamber's turn: CAN has its own bound
  // Every exchange of both ends by the budget's end: a chamber that used most of it leaves the
  // turntable the rest, never a whole timeout past the tick.
  std::optional<dr::ExchangeDeadline> cap;
  if (const auto end = budget.end()) cap.emplace(*end);
  if (plan.chamber) {
    Stopwatch w(field(times, &RigReadTimes::chamber));
    if (auto c = rig.chamber->read(); c) {
      r.chamber = c.value();
    } else {
      r.io_errors.push_back({"chamber", dr::to_string(c.error().kind)});
      r.chamber_error = c.error();
    }
  }
  Stopwatch w(field(times, &RigReadTimes::table));
  if (!rig.turntable || !plan.table) return;
  auto t = budget.spent("turntable");
  if (!t) {
    auto got = rig.turntable->read();
    if (got) r.table = got.value();
    if (got) r.table_interlock_open = r.table->interlock_open;
    if (!got) t = got.error();
  }
  if (t) {
    r.io_errors.push_back({"turntable", dr::to_string(t->kind)});
    r.table_error = std::move(t);
  }
}

void read_gpio(dr::gpio::GpioBank& bank, const RigReadPlan& plan, RigReading& r) {
  if (plan.gpio_edges) {
    if (auto ev = bank.read_events(); ev) r.edges = std::move(ev).value();
  }
  const auto level = [&](std::string_view role, std::optional<bool>& out) {
    if (dr::gpio::find_role(bank.config(), role) == nullptr) return;
    if (auto v = bank.read(role); v) {
      out = v.value();
    } else {
      r.io_errors.push_back({"gpio", dr::to_string(v.error().kind)});
      r.gpio_errors.emplace_back(std::string(role), v.error());
    }
  };
  level(dr::gpio::roles::interlock, r.door_closed);
  level(dr::gpio::roles::estop, r.estop_pressed);
}

}  // namespace

std::optional<double> RigReading::air_c() const {
  if (chamber && std::isfinite(chamber->air_c)) return chamber->air_c;
  return std::nullopt;
}

RigReading read_rig(Rig& rig, const RigReadPlan& plan, RigReadTimes* times) {
  RigReading r;
  r.has_table = rig.turntable != nullptr;
  if (plan.latch_seq) {
    // SYNC and collect before the Modbus reads. (Overlapping the boards' answers with the
    // Modbus reads measured slower on 2 cores: the simulators' threads compete for them.)
    Stopwatch w(field(times, &RigReadTimes::can));
    read_counters(rig, *plan.latch_seq, r);
  }
  read_devices(rig, plan, r, times);
  Stopwatch w(field(times, &RigReadTimes::gpio));
  if (rig.gpio) read_gpio(*rig.gpio, plan, r);
  return r;
}

std::vector<RigFault> rig_faults(const RigReading& r) {
  std::vector<RigFault> out;
  const auto fault = [&out](std::string key, std::string message) {
    out.push_back({std::move(key), std::move(message)});
  };
  // A link's message carries its reconnect countdown, which changes every second: the key names
  // the device and the error kind only.
  if (r.counters_error)
    fault(fmt::format("can {}", dr::to_string(r.counters_error->kind)), r.counters_error->message);
  if (r.chamber_error)
    fault(fmt::format("chamber {}", dr::to_string(r.chamber_error->kind)),
          r.chamber_error->message);
  if (r.chamber && r.chamber->alarms.any()) fault("chamber alarm", "chamber alarm");
  if (r.table_error)
    fault(fmt::format("turntable {}", dr::to_string(r.table_error->kind)), r.table_error->message);
  if (r.table && r.table->fault) fault("turntable fault", "turntable drive fault");
  // An e-stop chain that cuts the drive's enable shows here (docs/SIMRIG.md).
  if (r.table_interlock_open.value_or(false))
    fault("turntable interlock", "turntable interlock open");
  for (const auto& [role, e] : r.gpio_errors)
    fault(fmt::format("gpio {} {}", role, dr::to_string(e.kind)), e.message);
  if (r.estop_pressed.value_or(false)) fault("e-stop", "e-stop pressed");
  if (r.door_closed && !*r.door_closed) fault("door", "door open");
  return out;
}

}  // namespace station
