// The rig read once: one value per tick with every device's state or the error that kept it.
// The sequencer (running), the idle watch (between runs), `station probe` and the start check all
// read the rig through read_rig(), and every input has one name everywhere: `door_closed` (the
// GPIO interlock line, closed = safe), `estop_pressed` (the GPIO e-stop line),
// `table_interlock_open` (the turntable's own interlock bit). What is wrong with a reading is
// judged in one place, rig_faults().
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/chamber/chamber.hpp"
#include "drivers/common/result.hpp"
#include "drivers/counters/counter_boards.hpp"
#include "drivers/gpio/gpio_bank.hpp"
#include "drivers/turntable/turntable.hpp"
#include "station/daemon/rig.hpp"

namespace station {

/// One device I/O failure of a tick (metrics): device ("chamber", "turntable", "can", "gpio")
/// and drivers::ErrorKind by name.
struct IoError {
  std::string device, kind;
};

/// Wall seconds the chamber's and the turntable's exchanges of one 1 s tick may take together
/// (issue 34): each exchange has its own deadline (the device's timeout_s), but a chamber slow on
/// every exchange, or configured with a long timeout, must not push the turntable's read, and
/// with it the tick, past the tick's second. Of the second, the counter boards' latch before
/// them has its own bound (`[can] tick_timeout_ms`, 0.2 s by default), 0.6 s is theirs, and
/// 0.2 s is left for what follows the reading: the samples' store commit, safety and the
/// commands it sends. Every exchange of both ends by the budget's end at the latest
/// (drivers/common/exchange_deadline.hpp), and a device whose turn comes after it is not read
/// this tick: a timeout, never its last state passed as fresh.
inline constexpr double kTickReadBudgetS = 0.6;

/// What to read. A run reads everything each tick; between ticks only the GPIO inputs.
struct RigReadPlan {
  std::optional<std::uint8_t> latch_seq;  ///< SYNC the counter boards with it (none: no SYNC)
  bool chamber = true;                    ///< read the chamber
  bool table = true;                      ///< read the turntable (when configured)
  bool gpio_edges = true;                 ///< collect the GPIO bank's edges first
  /// Wall seconds from the chamber's turn after which the chamber and the turntable are no longer
  /// asked (none: no bound). The counter boards' latch has its own bound, and the GPIO lines
  /// are local reads: both always read.
  std::optional<double> budget_s;
};

/// Wall time per device of one reading, seconds (the sequencer's phase totals).
struct RigReadTimes {
  double can = 0, chamber = 0, table = 0, gpio = 0;
};

/// Every device's state at one tick, or the error that kept it (unset and no error: not read,
/// or not configured).
struct RigReading {
  std::optional<drivers::counters::TickResult> counters;
  std::optional<drivers::Error> counters_error;
  std::optional<drivers::ChamberState> chamber;
  std::optional<drivers::Error> chamber_error;
  bool has_table = false;
  std::optional<drivers::TurntableState> table;
  std::optional<drivers::Error> table_error;
  // The safety inputs, by their one name each (unset: not configured, or not readable).
  std::optional<bool> door_closed;           ///< GPIO interlock line: closed = safe
  std::optional<bool> estop_pressed;         ///< GPIO e-stop line
  std::optional<bool> table_interlock_open;  ///< the turntable's interlock bit
  std::vector<drivers::gpio::GpioEdge> edges;
  std::vector<std::pair<std::string, drivers::Error>> gpio_errors;  ///< role -> error
  std::vector<IoError> io_errors;  ///< every failure above, for metrics
  /// The chamber's air temperature when it read a finite one.
  std::optional<double> air_c() const;
};

/// Reads the rig once, in one fixed order (CAN SYNC and answers, chamber, turntable, GPIO edges,
/// interlock, e-stop: a recorded session replays in this order). Never throws for a device.
RigReading read_rig(Rig& rig, const RigReadPlan& plan, RigReadTimes* times = nullptr);

/// One thing wrong with the rig: a stable key (device and error kind, or the condition's name,
/// for change detection) and the message a person reads.
struct RigFault {
  std::string key, message;
};

/// What is wrong with `r` for starting or keeping a rig idle: each device that did not answer,
/// a chamber alarm, the table's drive fault or interlock, the door open, the e-stop pressed.
/// The run's safety layer (safety.hpp) judges the same inputs with hold semantics on top.
std::vector<RigFault> rig_faults(const RigReading& r);

}  // namespace station
