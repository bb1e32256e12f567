// The station's record: runs, gyros, 1 Hz samples, bins, fits and events in one SQLite file.
// Each tick is one transaction, so a kill at any instant loses nothing committed and the run
// resumes from its last committed step.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "compensation/binning.hpp"
#include "compensation/fit.hpp"
#include "station/store/events.hpp"
#include "station/store/run_state.hpp"
#include "station/store/sqlite.hpp"

namespace station {

/// One stored event.
struct EventRow {
  double t_s = 0;
  std::string severity, source, kind, message;
  std::optional<std::string> data_json;
};

/// An 'outage_start' event without its end (Store::open_outages).
struct OpenOutageEvent {
  std::string device;  ///< the event's source
  double start_s = 0;  ///< the event's tick
  std::string error;   ///< its data's `error` (older databases: its message)
};

/// What a new run records about itself.
struct RunInfo {
  std::string protocol_name, protocol_text, config_text, software_version, station, operator_name;
  std::optional<std::int64_t> sim_seed;
  double t0_wall_s = 0;       ///< wall-clock seconds (Unix) at t_s = 0
  std::string resolved_json;  ///< what gives a sample its meaning (resume.hpp), compared on resume
};

/// Where a run is in its protocol (updated with every tick).
struct RunProgress {
  int step_index = 0;
  double step_started_s = 0;
  bool recording = false;
  std::optional<double> record_start_s;
  std::optional<double> start_temp_c;  ///< chamber air at the run's first tick
};

/// A run as stored.
struct RunRecord {
  std::int64_t id = 0;
  RunState state = RunState::running;
  std::string protocol_name, protocol_text, config_text, station;
  std::optional<std::int64_t> sim_seed;
  double t0_wall_s = 0;
  std::string resolved_json;
  RunProgress progress;
  std::optional<double> last_tick_s;   ///< the last committed tick; empty before the first
  std::string started_utc, ended_utc;  ///< ISO-8601 UTC; ended_utc empty while running
  std::string software_version, operator_name;
};

/// One gyro on a run.
struct RunSlot {
  /// slot: the index of the configuration's [[slot]] table, from 0 (as stored since version 1);
  /// people count slots from 1 (`--slot N`, the start form): slot N is index N - 1.
  int slot = 0, node = 0;
  std::string serial, axis;
  double pulse_weight_arcsec = 0, earth_rate_dph = 0;
  /// Where the serial came from: "start" (given with the run), "config" (the configuration's
  /// default); empty: not known (stored before migration 11, or not read back).
  std::string gyro_source;
};

/// Flag bits stored with every sample (column samples.flags).
enum SampleFlag : int {
  kLatchLost = 1 << 0,       ///< no counter answer this tick (the next delta spans the gap)
  kChamberMissing = 1 << 1,  ///< the chamber did not answer
  kTempsMissing = 1 << 2,    ///< the gyro's temperatures did not arrive or failed
  kBoardFault = 1 << 3,      ///< the board reported a fault flag
  kSafeHold = 1 << 4,        ///< the rig was in safe hold (door open / e-stop)
  /// An acceptance step ran (rate_ladder, positions, power_cycles: the gyros switched, the
  /// table turned), or the table turned (faster than 0.001 deg/s): the rate is no thermal bias
  /// (issue 36).
  kAcceptanceStep = 1 << 5,
};
/// Samples with these flags are recorded but left out of the bins.
inline constexpr int kUnfitFlags = kBoardFault | kSafeHold | kAcceptanceStep;

/// One gyro's 1 Hz sample.
struct SampleRow {
  std::string serial;
  double t_s = 0;
  std::optional<std::int64_t> net_pulses;  ///< empty when the latch was lost
  std::optional<double> interval_s, rate_dph, temp_c, temp2_c, air_c, setpoint_c;
  int flags = 0;
  bool recording = false;
};

/// The one rule for a usable measurement: rate and both temperatures present, and not flagged
/// safe-hold or board fault (kUnfitFlags).
inline bool sample_is_usable(const SampleRow& s) {
  return s.rate_dph && s.temp_c && s.temp2_c && (s.flags & kUnfitFlags) == 0;
}
/// The one rule for which recorded 1 Hz samples go into bins: usable and in the record window.
inline bool sample_goes_into_bins(const SampleRow& s) {
  return s.recording && sample_is_usable(s);
}
/// The temperature gradient inside the gyro, the paper's gradT: second sensor minus first (the
/// convention of `analyze --temp2-col` and of the simulator), C; empty without both.
inline std::optional<double> gradient_c(const SampleRow& s) {
  if (!s.temp_c || !s.temp2_c) return std::nullopt;
  return *s.temp2_c - *s.temp_c;
}

/// The range of temperature and gradient a fit saw: over the 1 Hz samples of its complete bins.
struct FitSpan {
  double temp_min_c = 0, temp_max_c = 0;
  double grad_min_c = 0, grad_max_c = 0;
  bool operator==(const FitSpan&) const = default;
};

/// A stored fit.
struct FitRecord {
  std::int64_t id = 0;
  std::string serial, created_utc, terms;
  std::vector<std::int64_t> runs;
  compensation::FitResult fit;
  compensation::Evaluation eval;
  std::optional<FitSpan> span;  ///< empty: fitted before migration 8, or over older bins
};

/// Typed access to the station database. Not thread-safe: one writer (the sequencer).
class Store {
 public:
  /// Opens `path` as `mode` allows and migrates it (not in read_only); throws SqliteError.
  explicit Store(const std::string& path, OpenMode mode = OpenMode::create);

  std::int64_t create_run(const RunInfo& info, const std::vector<RunSlot>& slots);
  std::optional<RunRecord> find_run(std::int64_t id);
  /// The newest run still in state 'running' (a daemon killed mid-run), if any.
  std::optional<RunRecord> find_unfinished_run();
  std::vector<RunSlot> run_slots(std::int64_t run_id);
  void finish_run(std::int64_t run_id, RunState state);

  /// Tick `t_s`: its samples, the run's progress and t_s as the run's last tick, committed
  /// together with the ticks of its batch (see set_ticks_per_commit); a kill loses only ticks
  /// not yet committed. The progress row is written once per batch, by its commit: the last
  /// tick's, in the transaction of its samples, so the two never disagree. Samples are plain
  /// INSERTs: a tick stored twice throws, never replaces.
  void append_tick(std::int64_t run_id, double t_s, const std::vector<SampleRow>& rows,
                   const RunProgress& p);
  /// Ticks per transaction: 1 (default) on real hardware, where a tick is a second; the
  /// simulated clock batches, as a commit costs more than a simulated tick.
  void set_ticks_per_commit(int n) { ticks_per_commit_ = n < 1 ? 1 : n; }
  /// Commits an open batch of ticks.
  void flush();
  /// Rolls an open batch of ticks back, as a kill before its commit loses it (replay).
  void discard();
  ~Store();
  /// Samples of one serial in a run, by time (recording window only when asked).
  /// (SampleReader: the same, a row at a time.)
  std::vector<SampleRow> samples(std::int64_t run_id, const std::string& serial,
                                 bool recording_only);
  /// Number of samples stored for a run.
  std::int64_t sample_count(std::int64_t run_id);

  void replace_bins(std::int64_t run_id, const std::string& serial,
                    const std::vector<compensation::Bin>& bins, double earth_rate_dph);
  /// Complete bins of a serial over runs, as model data (bias = rate - Earth rate).
  compensation::ModelData model_data(const std::string& serial,
                                     const std::vector<std::int64_t>& runs);
  /// Run ids that recorded `serial`.
  std::vector<std::int64_t> runs_of_serial(const std::string& serial);

  /// The span of the complete bins of `serial` over `runs` (their stored ranges); empty when a
  /// complete bin was stored before migration 8 or there is none.
  std::optional<FitSpan> bins_span(const std::string& serial,
                                   const std::vector<std::int64_t>& runs);

  std::int64_t save_fit(const std::string& serial, const std::vector<std::int64_t>& runs,
                        const compensation::FitResult& fit, const compensation::Evaluation& eval,
                        const std::optional<FitSpan>& span = std::nullopt);
  std::optional<FitRecord> latest_fit(const std::string& serial);
  /// Fit `fit_id`; empty when there is none.
  std::optional<FitRecord> find_fit(std::int64_t fit_id);
  /// The newest fit of `serial` whose runs include `run_id` (the report of that run).
  std::optional<FitRecord> latest_fit_of_run(const std::string& serial, std::int64_t run_id);

  /// Stores an event; returns its id (events.id, increasing). `data` (column events.data_json,
  /// migration 2; NULL when null) has the fields schemas/events.md lists for `kind`.
  std::int64_t add_event(std::optional<std::int64_t> run_id, double t_s, Severity severity,
                         const std::string& source, EventKind kind, const std::string& message,
                         const nlohmann::json& data = nullptr);
  /// Events of a run as "kind: message" in order.
  std::vector<std::string> events(std::int64_t run_id);
  /// Events of a run, in order, every column.
  std::vector<EventRow> event_rows(std::int64_t run_id);
  /// Outages a run's events opened (kind 'outage_start') and never ended (no later 'outage'
  /// event of the same source): what a killed daemon left open, for the resumed one to carry on.
  std::vector<OpenOutageEvent> open_outages(std::int64_t run_id);

  Database& db() { return db_; }
  /// Statement `sql` prepared once per Store and reused: for statements run once per serial
  /// (`fit --all` over a thousand serials), where preparing would cost more than running.
  StatementLease cached(const std::string& sql);

 private:
  /// The progress of a batch's last tick, written by its commit (flush).
  struct PendingProgress {
    std::int64_t run_id = 0;
    double t_s = 0;
    RunProgress progress;
  };
  void insert_samples(std::int64_t run_id, const std::vector<SampleRow>& rows);
  void write_progress(const PendingProgress& w);

  Database db_;
  // The 1 Hz path's statements, prepared once (preparing costs more than the inserts).
  std::optional<Statement> insert_sample_, update_progress_;
  std::optional<Transaction> batch_;
  std::optional<PendingProgress> pending_progress_;
  std::unordered_map<std::string, Statement> cache_;  // by SQL text; nodes never move
  int ticks_per_commit_ = 1, batch_ticks_ = 0;
};

/// The samples of one serial in a run, by time, read a row at a time (what Store::samples
/// returns, without holding them).
class SampleReader {
 public:
  SampleReader(Store& store, std::int64_t run_id, const std::string& serial, bool recording_only);
  /// The next sample into `row`; false after the last.
  bool next(SampleRow& row);

 private:
  Statement st_;
  std::string serial_;
};

/// Current UTC time as ISO-8601 with milliseconds.
std::string utc_now_iso();

}  // namespace station
