// The 1 Hz loop (gpsd's main loop, small): each tick SYNC the counter boards, read chamber and
// turntable, assemble one sample per gyro, store the tick in one transaction, advance the
// protocol through the safety layer, sleep to the next absolute deadline. One device failing
// never stops the loop: it is reported, retried, and the safety layer owns the safe state.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "drivers/common/clock.hpp"
#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/daemon/outages.hpp"
#include "station/daemon/outputs.hpp"
#include "station/daemon/plausibility.hpp"
#include "station/daemon/protocol_runner.hpp"
#include "station/daemon/rig.hpp"
#include "station/daemon/rig_reading.hpp"
#include "station/daemon/safety.hpp"
#include "station/daemon/setpoint_watch.hpp"
#include "station/parts/part_file.hpp"
#include "station/store/calibration.hpp"
#include "station/store/store.hpp"

namespace station {

/// One tick's summary for progress lines, the live page and metrics.
/// The share of the tick's period its device I/O may take, reads and commands alike (the
/// reads' own kTickReadBudgetS within it): the rest (0.1 s of the 1 s tick) is the store's
/// transaction and the margin to the next tick's deadline, so a device whose replies drip or
/// never come costs no tick. A command whose turn comes after it is not sent this tick; it is
/// retried next tick, as a failed command is.
inline constexpr double kTickIoShare = 0.9;

struct TickReport {
  double t_s = 0;
  int step_index = 0;
  int steps = 0;
  bool recording = false;
  bool safe_hold = false;
  std::optional<double> air_c;
  std::int64_t run_id = 0;
  std::string step_label;
  std::optional<double> target_c;      ///< the protocol's target in force (a ramp's end), deg C
  std::optional<double> start_temp_c;  ///< the run's start temperature (to_start steps), deg C
  std::optional<double> time_left_s;   ///< by the protocol's steps (daemon/time_left.hpp)
  std::optional<drivers::ChamberState> chamber;  ///< empty: not read this tick
  std::optional<drivers::TurntableState> table;
  std::optional<bool> door_closed, estop_pressed, table_interlock_open;  ///< safety inputs
  const std::vector<SampleRow>* rows = nullptr;  ///< this tick's samples (valid during the call)
  std::vector<IoError> io_errors;
  double tick_wall_s = 0;    ///< wall time the tick took (devices, safety, store)
  std::int64_t skipped = 0;  ///< deadlines missed just before this tick (overrun)
  bool replaying = false;    ///< a resumed simulation recomputing stored ticks
};

/// An event as the sequencer stores it (SequencerOptions::on_event).
struct RunEvent {
  std::int64_t id = 0;  ///< events.id
  std::int64_t run_id = 0;
  double t_s = 0;
  Severity severity = Severity::info;
  std::string source;
  EventKind kind = EventKind::done;
  std::string message;
  nlohmann::json data = nullptr;  ///< the kind's fields (schemas/events.md), or null
};

/// How to run.
struct SequencerOptions {
  double period_s = 1.0;
  std::string operator_name;
  std::optional<std::int64_t> sim_seed;            ///< recorded with the run
  std::function<void(double t_s)> before_tick;     ///< simulation: advance the world to t_s
  std::function<void(const TickReport&)> on_tick;  ///< progress / tests
  std::function<void()> watchdog;                  ///< systemd WATCHDOG=1 each tick
  const std::atomic<bool>* stop = nullptr;         ///< set by SIGTERM/SIGINT
  /// Ends the run at the next tick without binning or fitting: state 'aborted' (API abort).
  const std::atomic<bool>* abort = nullptr;
  /// Ends the loop at the next tick leaving the run 'running', exactly as a kill would but with
  /// everything committed: the next daemon resumes it (a package upgrade's restart, SIGUSR1 to
  /// `serve`). No bins, no fit, outputs not driven (serve then leaves with _Exit, so the GPIO
  /// bank's release does not drive them safe either). Outcome state 'detached'.
  const std::atomic<bool>* detach = nullptr;
  /// Told each stored event (the live page's event stream). Called on the sequencer's thread.
  std::function<void(const RunEvent&)> on_event;
  /// Where the live page is served (an 'http' event at the run's start or resume: the port a
  /// `--http HOST:0` chose is in the run's record).
  std::string http_url;
  /// Told the run's id, protocol (as clamped) and slots once it is created or resumed, before
  /// the first tick.
  std::function<void(std::int64_t run_id, const Protocol& protocol,
                     const std::vector<RunSlot>& slots)>
      on_run_start;
  /// Deterministic simulation resume: replay ticks up to this time without storing them.
  std::optional<double> replay_until_t_s;
  /// A resumed run's first tick as a recorded daemon chose it (from the wall clock): a session
  /// replay of a rig resume (station/session). Never before the tick after the last committed.
  std::optional<double> resume_at_t_s;
  /// Told, before any device I/O, that a run resumes: last committed tick, first tick now.
  std::function<void(double last_s, double next_s)> on_resume;
  /// Part limits by serial (slot_part_limits): each such gyro's fit is judged and its verdict
  /// stored and logged. Empty: no verdicts (and no verdict events).
  std::map<std::string, PartLimits> part_limits;
};

/// How a run ended.
struct RunOutcome {
  std::int64_t run_id = 0;
  RunState state = RunState::completed;  ///< completed | incomplete | stopped | aborted | detached
  double t_s = 0;                        ///< last tick
  std::int64_t ticks = 0;
};

/// Runs one protocol on one rig. Not thread-safe.
class Sequencer {
 public:
  Sequencer(const StationConfig& config, const Protocol& protocol, Rig& rig, Store& store,
            drivers::Clock& clock, SequencerOptions options);

  /// Starts a new run, or continues `resume` (a run left 'running' by a killed daemon).
  RunOutcome run(const std::optional<RunRecord>& resume = std::nullopt);

 private:
  /// Everything one tick read, and what the sequencer made of it.
  struct TickData {
    RigReading in;  ///< the rig, read once (rig_reading.hpp)
    std::vector<SampleRow> rows;
    Observation obs;
    bool air_implausible = false;  ///< the chamber's air was taken out as implausible
  };
  /// The tick's summary for SequencerOptions::on_tick.
  TickReport report(double t_s, const TickData& d) const;
  /// The first tick of a resumed run, strictly after its last committed one; logs the resume.
  double resume_first_tick(const RunRecord& resume);
  /// Outages the killed daemon left open go on in this process (one event when they end).
  void restore_outages(std::int64_t run_id, double last_s);
  void connect_devices();
  /// The 1 Hz loop from `t_first` to the run's end.
  RunOutcome tick_loop(double t_first);
  void create_run();
  RunOutcome guarded_tick_loop(double t_first);
  /// The run's end after tick `t_s`, if this tick ends it (abort, detach, stop, protocol done).
  std::optional<RunOutcome> end_of_run(double t_s, std::int64_t ticks);
  /// `skipped` ticks before `t_s` were missed (the process was stopped or late): a tick_gap event.
  void note_tick_gap(double t_s, std::int64_t skipped);
  void tick(double t_s, TickData& d);
  void read_devices(double t_s, TickData& d);
  /// Takes implausible readings out of `d.in` (plausibility.hpp), one event per episode.
  void screen(double t_s, TickData& d);
  /// The chamber's setpoint against the station's (setpoint_watch.hpp): events, a restore.
  void check_setpoint(double t_s, const TickData& d);
  /// The chamber accepted `c`: its setpoint is the station's now.
  void note_commanded(const drivers::ChamberCommand& c);
  /// Why no more device I/O goes out this tick (its kTickIoShare is spent), or nothing.
  std::optional<drivers::Error> io_spent(const char* what) const;
  /// The device commands of a tick, each within its I/O budget (io_spent: not sent, an error
  /// to retry next tick); the chamber's setpoint told to the setpoint watch as tried,
  /// accepted, or failed with its outcome known or not.
  drivers::Result<void> command_chamber(const drivers::ChamberCommand& c);
  drivers::Result<void> command_table(const drivers::TurntableCommand& c);
  drivers::Result<void> stop_table();
  /// At the end of a run whose protocol left the table released: a controlled stop.
  void rest_table(double t_s);
  void apply_safety(double t_s, TickData& d);
  /// Stores an event per GPIO edge of a reading.
  void note_edges(double t_s, const RigReading& in);
  void watch_inputs_until(double deadline_s, double t_s);
  /// Carries out a safety decision: its events, hold commands (acknowledged back), outputs.
  void act_on_safety(double t_s, const SafetyDecision& d);
  void apply_actions(double t_s, const Actions& a);
  /// Tower lamps and gyro power relays (configured ones); writes the lines that change.
  void drive_outputs(double t_s, SafetyOutputs o);
  void assemble_samples(double t_s, TickData& d);
  /// Ends the run: closes open outages, bins and fits; returns the final state ('incomplete'
  /// instead of 'completed' when a slot lost more than max_lost_share of its record window).
  RunState finish(RunState state, double t_s);
  /// Ends the run without bins or fit (SequencerOptions::abort): state 'aborted'.
  RunState abort(double t_s);
  /// Judges a slot's fit against its part (options_.part_limits): verdict stored and an event.
  void judge(double t_s, const SerialFit& f);
  /// Stores each slot's part and a snapshot of its limits with a new run.
  void save_parts();
  /// Stores an event of the run (not while a resumed simulation replays) and tells on_event.
  void emit(double t_s, Severity severity, const std::string& source, EventKind kind,
            const std::string& message, const nlohmann::json& data = nullptr);
  void emit(double t_s, const std::string& source, const EventNote& e) {
    emit(t_s, e.severity, source, e.kind, e.message, e.data);
  }
  /// Outage bookkeeping: one tick's news about a device (see OutageTracker::observe).
  void note_link(double t_s, const std::string& device, std::optional<bool> answered,
                 const std::string& error);
  /// The bus and every board, and board resets / re-baselines, from one counter tick.
  void note_counters(double t_s, const TickData& d, const std::string& error);
  /// Ends open outages at the run's last tick and judges every slot's record window: per slot
  /// that lost more than max_lost_share, a warning (also an event) for its fit.
  std::map<std::string, std::string> close_outages(double t_s);

  const StationConfig& config_;
  Protocol protocol_;  ///< the protocol as clamped to the station's limits
  Rig& rig_;
  Store& store_;
  drivers::Clock& clock_;
  SequencerOptions options_;
  Safety safety_;
  std::optional<ProtocolRunner> runner_;
  std::int64_t run_id_ = 0;
  double last_t_s_ = 0;  ///< the tick being run (where a store failure happened)
  std::uint8_t latch_seq_ = 0;
  bool replaying_ = false;
  int command_failures_ = 0;
  /// When this tick's device I/O must end (kTickIoShare of the period from its start), on the
  /// steady clock the exchanges run on; none between ticks.
  std::optional<std::chrono::steady_clock::time_point> io_end_;
  OutageTracker outages_;             ///< link outages per device
  PlausibilityWatch plausibility_;    ///< implausible readings, per episode
  SetpointWatch setpoint_watch_;      ///< the chamber's setpoint against the station's
  std::optional<double> last_air_c_;  ///< last chamber air reading
  RigOutputs outputs_;                ///< lamps and relays, written where they change
  /// Time spent per tick phase (wall seconds, summed), logged at the end of a run.
  struct PhaseTimes {
    double world = 0, store = 0;
    RigReadTimes rig;
  } phase_s_;
  std::optional<drivers::ChamberCommand> pending_chamber_;
  std::optional<drivers::TurntableCommand> pending_table_;
  /// The protocol released the table's lock (an acceptance step turns it) and has not locked it
  /// again: a run that ends so stops the table (rest_table).
  bool table_released_ = false;
};

}  // namespace station
