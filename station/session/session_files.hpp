// The session directory's two summary files (schemas/session.md): session.toml, what the run
// was (written when it starts), and result.json, what it produced (written when it ends).
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station {

/// The session format's version (schemas/session.md, "Versions").
inline constexpr int kSessionFormatVersion = 3;

/// What session.toml holds.
struct SessionHeader {
  std::string station, software_version, started_utc;
  double latitude_deg = 0;
  bool simulated = false;
  std::optional<std::int64_t> sim_seed;
  std::string config_text;    ///< the station configuration as given (TOML)
  std::string resolved_json;  ///< what gives the samples their meaning (resolved_meaning_json)
  std::string protocol_name, protocol_text;
  std::vector<RunSlot> slots;
};

/// The file a session's `path` is read from: `path`, or `path`.gz when only that exists (`path`
/// when neither does: the caller says it is missing). Both at once is refused (InputError naming
/// both): which one the run wrote cannot be told, and a check of one would vouch for the other.
/// The one rule of every reader of a session (logs, result.json, digest.txt).
std::string session_file(const std::string& path);

/// Whether `path` or `path`.gz exists.
bool session_file_exists(const std::string& path);

/// Writes `dir`/session.toml unless it exists (a resumed run keeps the header of its start).
/// Throws InputError naming the path when it cannot be written.
void write_session_header(const std::string& dir, const SessionHeader& header);

/// Where a killed run was resumed: the last tick its store had committed, and how many lines
/// each log held when the resumed daemon began (what the killed daemon wrote).
struct SessionResume {
  double after_tick_s = 0;
  std::optional<double> next_tick_s;  ///< the resumed daemon's first tick (rig: wall clock)
  std::int64_t can_lines = 0, modbus_lines = 0, gpio_lines = 0, ascii_lines = 0;
};

/// Marks a resume in `dir`: cuts a line the killed daemon left half-written from each log, counts
/// the logs' lines and appends a [[resume]] table to session.toml. Throws InputError.
void append_session_resume(const std::string& dir, double after_tick_s, double next_tick_s);

/// The [[resume]] tables of a session.toml (empty for a run recorded without a restart).
std::vector<SessionResume> read_session_resumes(const std::string& session_toml_path);

/// How the run ended (session.toml [[end]], the last one): its state and the tick it ended at. A
/// replay stops (or aborts) its run at that tick, as the operator's stop did.
struct SessionEnd {
  std::string state;  ///< completed | incomplete | stopped | aborted
  double last_tick_s = 0;
};

/// Appends an [[end]] table to `dir`/session.toml. Throws InputError.
void append_session_end(const std::string& dir, const SessionEnd& end);

/// The last [[end]] table of a session.toml; throws InputError naming the file when it is missing
/// or malformed (a session whose run did not end cannot be replayed).
SessionEnd read_session_end(const std::string& session_toml_path);

/// What run `run_id` stored, as result.json holds it: every tick's samples, every bin, every
/// event and every fit of the run.
nlohmann::json session_result_json(Store& store, std::int64_t run_id);

/// result.json without its ticks: format_version, run_id, state, sample_columns, bins, events,
/// fits.
nlohmann::json session_result_head_json(Store& store, std::int64_t run_id);

/// The names of a tick's sample rows' columns, in order (result.json "sample_columns").
const std::vector<std::string>& sample_columns();

/// One stored sample as result.json keeps it: an array in sample_columns() order.
nlohmann::json sample_row_json(const SampleRow& r);

/// Column `column` of sample_row_json(r) when it is a number (columns 1..8; null: empty), without
/// building the JSON — for comparing millions of rows.
std::optional<double> sample_number(const SampleRow& r, std::size_t column);

/// The run's stored ticks one at a time, in time order, with the samples of a tick in slot order:
/// read from the store as they are asked for (a row ahead per slot), never held whole.
class TickCursor {
 public:
  TickCursor(Store& store, std::int64_t run_id);
  /// The next tick's time and samples (pointers valid until the next call); false at the end.
  bool next(double& t_s, std::vector<const SampleRow*>& rows);

 private:
  std::vector<SampleReader> readers_;            // per slot
  std::vector<std::optional<SampleRow>> ahead_;  // per slot: its next sample
  std::vector<SampleRow> taken_;                 // per slot: the tick's sample handed out
};

/// Calls `each(t_s, rows)` for every tick of the run in time order, with the stored samples of
/// that tick in slot order.
void for_each_tick(Store& store, std::int64_t run_id,
                   const std::function<void(double, const std::vector<const SampleRow*>&)>& each);

/// One tick as result.json keeps it: [t_s, row, row, ...].
nlohmann::json tick_json(double t_s, const std::vector<const SampleRow*>& rows);

/// Writes session_result_json to `dir`/result.json (replacing it). Throws InputError.
void write_session_result(Store& store, std::int64_t run_id, const std::string& dir);

}  // namespace station
