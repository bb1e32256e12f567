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

/// positions: the longest the runner waits for the table to report in position at a point's
/// angle before that point's settle time starts, s. A table still moving after it has faulted
/// (a half turn at 1 deg/s takes 180 s): the point is left out, said in its event.
inline constexpr double kPositionMoveDeadlineS = 300.0;

class AcceptanceRunner {
 public:
  /// Enters `step` (step `step_index`, started at run time `started_s`). Entering the same step
  /// again (after a safe hold) keeps the point being measured and sends its demand again.
  void enter(const Step& step, int step_index, double started_s);
  /// One tick at run time `t_s`. positions: a table not yet in position at the point's angle
  /// when its settle_s (counted from the demand) is over holds the schedule's clock there until
  /// it is (at most kPositionMoveDeadlineS after the demand), then settle_s runs again from its
  /// arrival: a move longer than settle_s delays the step, and its point is measured whole.
  /// A table there within settle_s keeps the schedule as it was. Each point's event gives the
  /// window it measured.
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
  /// positions: holds the schedule's clock at the window's start while the move is under way.
  void wait_for_table(const AcceptancePoint& p, double t_s, const TableObservation& table);
  /// The time into the step on the schedule's clock: run time less the moves waited for, s.
  double schedule_s(double t_s) const { return t_s - started_s_ - waited_s_; }

  const Step* step_ = nullptr;
  int step_index_ = -1;
  double started_s_ = 0;
  std::vector<AcceptancePoint> points_;
  double duration_s_ = 0;  ///< acceptance_duration_s of the step, taken at enter, s
  int current_ = -1;       ///< point whose demand was sent
  bool resend_ = false;    ///< entered again: send the current demand at the next tick
  bool rested_ = false;    ///< the end-of-step demand was sent
  bool power_on_ = true;
  bool cut_ = false;     ///< the current point's window was interrupted (a safe hold): left out
  double waited_s_ = 0;  ///< positions: the moves waited for so far in this step, s
  std::optional<double> sent_s_;  ///< positions: when the current point's demand went out
  bool arrived_ = true;           ///< positions: the table reported in position at the angle
  bool holding_ = false;          ///< positions: the clock is held at the window's start
  bool unreached_ = false;        ///< positions: the deadline passed first: the point is left out
  PointStats stats_;
};

}  // namespace station
