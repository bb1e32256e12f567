// Store: typed reads and writes over the migrated SQLite schema (schemas/migrations).
#include "station/store/store.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>

#include <chrono>
#include <nlohmann/json.hpp>

#include "station/common/logging.hpp"
#include "station/store/fit_json.hpp"

namespace station {

namespace sc = station::compensation;
using nlohmann::json;

std::string utc_now_iso() {
  const auto now = std::chrono::system_clock::now();
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()) % 1000;
  return fmt::format("{:%Y-%m-%dT%H:%M:%S}.{:03d}Z",
                     fmt::gmtime(std::chrono::system_clock::to_time_t(now)),
                     static_cast<int>(ms.count()));
}

Store::Store(const std::string& path, OpenMode mode) : db_(path, mode) {
  db_.migrate();
}

StatementLease Store::cached(const std::string& sql) {
  auto it = cache_.find(sql);
  if (it == cache_.end()) it = cache_.emplace(sql, db_.prepare(sql)).first;
  return StatementLease(it->second);
}

std::int64_t Store::create_run(const RunInfo& info, const std::vector<RunSlot>& slots) {
  flush();
  Transaction tx(db_);
  auto st = db_.prepare(
      "INSERT INTO runs (started_utc, state, protocol_name, protocol_text, config_text, "
      "software_version, station, operator, sim_seed, t0_wall_s, resolved_json) "
      "VALUES (?,?,?,?,?,?,?,?,?,?,?)");
  st.bind(1, utc_now_iso()).bind(2, to_string(RunState::running));
  st.bind(3, info.protocol_name).bind(4, info.protocol_text);
  st.bind(5, info.config_text).bind(6, info.software_version).bind(7, info.station);
  st.bind(8, info.operator_name);
  if (info.sim_seed)
    st.bind(9, *info.sim_seed);
  else
    st.bind_null(9);
  st.bind(10, info.t0_wall_s).bind(11, info.resolved_json.empty() ? "{}" : info.resolved_json);
  st.step();
  const std::int64_t id = db_.last_insert_id();
  auto gyro = db_.prepare("INSERT OR IGNORE INTO gyros (serial, first_seen_utc) VALUES (?, ?)");
  auto slot = db_.prepare(
      "INSERT INTO run_slots (run_id, slot, node, serial, pulse_weight_arcsec, axis, "
      "earth_rate_dph, gyro_source) VALUES (?,?,?,?,?,?,?,?)");
  for (const auto& s : slots) {
    gyro.bind(1, s.serial).bind(2, utc_now_iso());
    gyro.step();
    gyro.reset();
    slot.bind(1, id).bind(2, s.slot).bind(3, s.node).bind(4, s.serial);
    slot.bind(5, s.pulse_weight_arcsec).bind(6, s.axis).bind(7, s.earth_rate_dph);
    if (s.gyro_source.empty())
      slot.bind_null(8);
    else
      slot.bind(8, s.gyro_source);
    slot.step();
    slot.reset();
  }
  tx.commit();
  return id;
}

namespace {
constexpr const char* kRunColumns =
    "SELECT id, state, protocol_name, protocol_text, config_text, station, sim_seed, step_index, "
    "step_started_s, t_s, recording, record_start_s, start_temp_c, t0_wall_s, resolved_json, "
    "started_utc, ended_utc, software_version, operator FROM runs ";

RunRecord read_run(const Statement& st) {
  RunRecord r;
  r.id = st.column_int(0);
  const std::string state = st.column_text(1);
  const auto parsed = parse_run_state(state);
  if (!parsed) throw SqliteError(fmt::format("run {}: unknown state '{}'", r.id, state));
  r.state = *parsed;
  r.protocol_name = st.column_text(2);
  r.protocol_text = st.column_text(3);
  r.config_text = st.column_text(4);
  r.station = st.column_text(5);
  if (!st.column_is_null(6)) r.sim_seed = st.column_int(6);
  r.progress.step_index = static_cast<int>(st.column_int(7));
  r.progress.step_started_s = st.column_double(8);
  if (!st.column_is_null(9)) r.last_tick_s = st.column_double(9);
  r.progress.recording = st.column_int(10) != 0;
  if (!st.column_is_null(11)) r.progress.record_start_s = st.column_double(11);
  if (!st.column_is_null(12)) r.progress.start_temp_c = st.column_double(12);
  r.t0_wall_s = st.column_double(13);
  r.resolved_json = st.column_text(14);
  r.started_utc = st.column_text(15);
  if (!st.column_is_null(16)) r.ended_utc = st.column_text(16);
  r.software_version = st.column_text(17);
  r.operator_name = st.column_text(18);
  return r;
}
}  // namespace

std::optional<RunRecord> Store::find_run(std::int64_t id) {
  auto st = cached(std::string(kRunColumns) + "WHERE id = ?");
  st->bind(1, id);
  if (!st->step()) return std::nullopt;
  return read_run(*st);
}

std::optional<RunRecord> Store::find_unfinished_run() {
  auto st = db_.prepare(std::string(kRunColumns) + "WHERE state = ? ORDER BY id DESC LIMIT 1");
  st.bind(1, to_string(RunState::running));
  if (!st.step()) return std::nullopt;
  return read_run(st);
}

std::vector<RunSlot> Store::run_slots(std::int64_t run_id) {
  auto st = db_.prepare(
      "SELECT slot, node, serial, pulse_weight_arcsec, axis, earth_rate_dph FROM run_slots "
      "WHERE run_id = ? ORDER BY slot");
  st.bind(1, run_id);
  std::vector<RunSlot> out;
  while (st.step()) {
    out.push_back({static_cast<int>(st.column_int(0)), static_cast<int>(st.column_int(1)),
                   st.column_text(2), st.column_text(4), st.column_double(3), st.column_double(5)});
  }
  return out;
}

void Store::finish_run(std::int64_t run_id, RunState state) {
  flush();
  auto st = db_.prepare("UPDATE runs SET state = ?, ended_utc = ? WHERE id = ?");
  st.bind(1, to_string(state)).bind(2, utc_now_iso()).bind(3, run_id);
  st.step();
}

void Store::append_tick(std::int64_t run_id, double t_s, const std::vector<SampleRow>& rows,
                        const RunProgress& p) {
  if (!insert_sample_) {
    // A committed sample is never replaced: a second tick at the same time is a bug that
    // must surface (the primary key fails), not be hidden.
    insert_sample_.emplace(db_.prepare(
        "INSERT INTO samples (run_id, serial, t_s, net_pulses, interval_s, rate_dph, temp_c, "
        "temp2_c, air_c, setpoint_c, flags, recording) VALUES (?,?,?,?,?,?,?,?,?,?,?,?)"));
    update_progress_.emplace(
        db_.prepare("UPDATE runs SET step_index = ?, step_started_s = ?, t_s = ?, recording = ?, "
                    "record_start_s = ?, start_temp_c = ? WHERE id = ?"));
  }
  if (!batch_) batch_.emplace(db_);
  try {
    insert_samples(run_id, rows);
  } catch (...) {
    discard();  // rolls back the whole batch: no half tick is ever committed
    throw;
  }
  // The run's progress is written once, by the batch's commit (flush), in the same transaction
  // as the samples: what a resume reads is the last committed tick's, as when every tick wrote
  // it, for one UPDATE (and one outbox trigger) per batch instead of one per tick.
  pending_progress_ = PendingProgress{run_id, t_s, p};
  if (++batch_ticks_ >= ticks_per_commit_) flush();
}

void Store::insert_samples(std::int64_t run_id, const std::vector<SampleRow>& rows) {
  auto& ins = *insert_sample_;
  for (const auto& r : rows) {
    ins.reset();
    ins.bind(1, run_id).bind(2, r.serial).bind(3, r.t_s);
    if (r.net_pulses)
      ins.bind(4, *r.net_pulses);
    else
      ins.bind_null(4);
    ins.bind(5, r.interval_s).bind(6, r.rate_dph).bind(7, r.temp_c).bind(8, r.temp2_c);
    ins.bind(9, r.air_c).bind(10, r.setpoint_c).bind(11, r.flags).bind(12, r.recording ? 1 : 0);
    ins.step();
  }
  ins.reset();
}

void Store::write_progress(const PendingProgress& w) {
  const auto& p = w.progress;
  auto& up = *update_progress_;
  up.reset();
  up.bind(1, p.step_index).bind(2, p.step_started_s).bind(3, w.t_s).bind(4, p.recording ? 1 : 0);
  up.bind(5, p.record_start_s).bind(6, p.start_temp_c).bind(7, w.run_id);
  up.step();
  up.reset();
}

void Store::discard() {
  batch_.reset();
  batch_ticks_ = 0;
  pending_progress_.reset();
}

void Store::flush() {
  if (!batch_) return;
  try {
    if (pending_progress_) write_progress(*pending_progress_);
    batch_->commit();
  } catch (...) {
    discard();  // the batch's ticks are lost (never committed); the next tick starts anew
    throw;
  }
  batch_.reset();
  batch_ticks_ = 0;
  pending_progress_.reset();
}

Store::~Store() {
  try {
    flush();
  } catch (...) {  // NOLINT(bugprone-empty-catch): the batch rolls back; nothing else to do here
  }
}

SampleReader::SampleReader(Store& store, std::int64_t run_id, const std::string& serial,
                           bool recording_only)
    : st_(store.db().prepare(fmt::format(
          "SELECT t_s, net_pulses, interval_s, rate_dph, temp_c, temp2_c, air_c, setpoint_c, "
          "flags, recording FROM samples WHERE run_id = ? AND serial = ? {} ORDER BY t_s",
          recording_only ? "AND recording = 1" : ""))),
      serial_(serial) {
  st_.bind(1, run_id).bind(2, serial);
}

bool SampleReader::next(SampleRow& r) {
  if (!st_.step()) return false;
  auto opt = [&](int c) {
    return st_.column_is_null(c) ? std::nullopt : std::optional(st_.column_double(c));
  };
  r.serial = serial_;
  r.t_s = st_.column_double(0);
  r.net_pulses = st_.column_is_null(1) ? std::nullopt : std::optional(st_.column_int(1));
  r.interval_s = opt(2);
  r.rate_dph = opt(3);
  r.temp_c = opt(4);
  r.temp2_c = opt(5);
  r.air_c = opt(6);
  r.setpoint_c = opt(7);
  r.flags = static_cast<int>(st_.column_int(8));
  r.recording = st_.column_int(9) != 0;
  return true;
}

std::vector<SampleRow> Store::samples(std::int64_t run_id, const std::string& serial,
                                      bool recording_only) {
  SampleReader reader(*this, run_id, serial, recording_only);
  std::vector<SampleRow> out;
  for (SampleRow r; reader.next(r);) out.push_back(r);
  return out;
}

std::int64_t Store::sample_count(std::int64_t run_id) {
  auto st = db_.prepare("SELECT count(*) FROM samples WHERE run_id = ?");
  st.bind(1, run_id);
  st.step();
  return st.column_int(0);
}

std::int64_t Store::add_event(std::optional<std::int64_t> run_id, double t_s, Severity severity,
                              const std::string& source, EventKind kind, const std::string& message,
                              const nlohmann::json& data) {
  // A kind's data follows its row in events.cpp (schemas/events.md); a slip is a bug to see in
  // the log, never a reason to lose the event.
  if (const auto why = event_mismatch(kind, severity, data); !why.empty())
    log("db")->error("event {} does not follow schemas/events.md: {}", to_string(kind), why);
  auto st = db_.prepare(
      "INSERT INTO events (run_id, t_s, wall_utc, severity, source, kind, message, data_json) "
      "VALUES (?,?,?,?,?,?,?,?)");
  if (run_id)
    st.bind(1, *run_id);
  else
    st.bind_null(1);
  st.bind(2, t_s).bind(3, utc_now_iso()).bind(4, to_string(severity)).bind(5, source);
  st.bind(6, to_string(kind)).bind(7, message);
  if (data.is_null())
    st.bind_null(8);
  else
    st.bind(8, data.dump());
  st.step();
  return db_.last_insert_id();
}

std::vector<std::string> Store::events(std::int64_t run_id) {
  auto st = db_.prepare("SELECT kind, message FROM events WHERE run_id = ? ORDER BY id");
  st.bind(1, run_id);
  std::vector<std::string> out;
  while (st.step()) out.push_back(st.column_text(0) + ": " + st.column_text(1));
  return out;
}

std::vector<EventRow> Store::event_rows(std::int64_t run_id) {
  auto st = db_.prepare(
      "SELECT t_s, severity, source, kind, message, data_json FROM events WHERE run_id = ? "
      "ORDER BY id");
  st.bind(1, run_id);
  std::vector<EventRow> out;
  while (st.step()) {
    EventRow e{st.column_double(0), st.column_text(1), st.column_text(2),
               st.column_text(3),   st.column_text(4), std::nullopt};
    if (!st.column_is_null(5)) e.data_json = st.column_text(5);
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<OpenOutageEvent> Store::open_outages(std::int64_t run_id) {
  auto st = db_.prepare(
      "SELECT source, MAX(t_s), message, data_json FROM events AS s WHERE run_id = ?1 AND "
      "kind = ?2 AND NOT EXISTS (SELECT 1 FROM events AS e WHERE e.run_id = ?1 AND "
      "e.source = s.source AND e.kind = ?3 AND e.id > s.id) GROUP BY source ORDER BY source");
  st.bind(1, run_id).bind(2, to_string(EventKind::outage_start));
  st.bind(3, to_string(EventKind::outage));
  std::vector<OpenOutageEvent> out;
  while (st.step()) {
    // The error is the data's (databases before issue 23 have it only in the message).
    const auto data = st.column_is_null(3)
                          ? nlohmann::json()
                          : nlohmann::json::parse(st.column_text(3), nullptr, false);
    const bool has_error = data.is_object() && data.contains("error") && data["error"].is_string();
    out.push_back({st.column_text(0), st.column_double(1),
                   has_error ? data["error"].get<std::string>() : st.column_text(2)});
  }
  return out;
}

}  // namespace station
