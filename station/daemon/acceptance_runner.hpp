// The acceptance steps carried out (issue 36): the table's demands and the gyros' power along a
// step's schedule (config/acceptance_steps.hpp), and one acceptance_point event per measured
// point with what the table did over its window. No I/O: the protocol runner asks it.
#pragma once

#include <optional>
#include <vector>

#include "drivers/turntable/turntable.hpp"
#include "station/config/acceptance_steps.hpp"
#include "station/config/config.hpp"
#include "station/store/events.hpp"

namespace station {

/// Refuses (InputError, before the run exists) a protocol whose acceptance steps this rig cannot
/// carry out: a rate_ladder or positions step without a turntable, a power_cycles step while a
/// slot has no relay (its gyro would never be switched off, and its turn-ons would be made up),
/// a rate_ladder asking a rate or an acceleration beyond the table's limits ([turntable]
/// max_rate_dps and max_accel_dps2, the dialect's own rate limit where lower). Called once for a
/// new run, before it is stored (Sequencer::create_run: run --config, serve, run --sim alike).
void check_acceptance_rig(const Protocol& protocol, const StationConfig& config,
                          bool has_turntable);

/// What the table showed this tick (empty: no answer).
struct TableObservation {
  std::optional<double> rate_dps, angle_deg;
  bool in_position = false;
};

/// What the acceptance step asks for this tick.
struct AcceptanceActions {
  std::optional<drivers::TurntableCommand> table;
  std::optional<bool> gyro_power;
  std::vector<EventNote> events;
};

class AcceptanceRunner {
 public:
  /// Enters `step` (step `step_index`, started at run time `started_s`). Entering the same step
  /// again (after a safe hold) keeps the point being measured and sends its demand again.
  void enter(const Step& step, int step_index, double started_s);
  /// One tick at run time `t_s`.
  AcceptanceActions tick(double t_s, const TableObservation& table);
  /// The whole schedule has run (the ladder's table back at rest).
  bool finished(double t_s) const;
  /// The step ends early (its timeout): the point being measured is closed (left out, its window
  /// cut short) and the table sent to rest, the gyros powered.
  AcceptanceActions leave();
  /// Whether the gyros are to be powered (false only in a power cycle's off time).
  bool gyro_power() const { return power_on_; }

 private:
  struct PointStats {
    int readings = 0;
    double sum = 0, max_dev = 0;
    bool all_in_position = true;
    std::optional<double> first_s, last_s;
  };
  void send(const AcceptancePoint& p, double t_s, AcceptanceActions& a);
  void measure(const AcceptancePoint& p, double t_s, const TableObservation& table);
  void close(const AcceptancePoint& p, AcceptanceActions& a);
  void rest(AcceptanceActions& a);

  const Step* step_ = nullptr;
  int step_index_ = -1;
  double started_s_ = 0;
  std::vector<AcceptancePoint> points_;
  double duration_s_ = 0;  ///< acceptance_duration_s of the step, taken at enter, s
  int current_ = -1;       ///< point whose demand was sent
  bool resend_ = false;    ///< entered again: send the current demand at the next tick
  bool rested_ = false;    ///< the end-of-step demand was sent
  bool power_on_ = true;
  bool cut_ = false;  ///< the current point's window was interrupted (a safe hold): left out
  PointStats stats_;
};

}  // namespace station
