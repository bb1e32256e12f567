// Replaying a session directory through the daemon (see session_replay.hpp).
#include "station/session/session_replay.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include "station/common/input_error.hpp"
#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/daemon/run_gyros.hpp"
#include "station/session/replay_daemons.hpp"
#include "station/session/replay_narration.hpp"
#include "station/session/session_digest.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_log.hpp"
#include "station/session/session_metadata.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;

std::string required_text(const toml::table& t, const std::string& path, const char* key) {
  const auto v = t[key].value<std::string>();
  if (!v) throw InputError(fmt::format("{}: key '{}': missing or not a string", path, key));
  return *v;
}

toml::table parse_header(const std::string& path) {
  if (!fs::exists(path)) throw InputError(fmt::format("{}: no such file (not a session)", path));
  try {
    return toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: {}", path, e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
}

/// Refuses a session of another format version (one line naming the file).
void check_version(const std::string& path, const toml::table& t) {
  const auto version = t["format_version"].value<std::int64_t>();
  if (version == kSessionFormatVersion) return;
  if (version && *version == 2)
    throw InputError(fmt::format(
        "{}: key 'format_version': 2 has no digest and no [end]: nothing proves its logs are "
        "the run's; re-record it (or replay it with the station that recorded it)",
        path));
  throw InputError(
      fmt::format("{}: key 'format_version': {} is not a version this station reads "
                  "({})",
                  path, version ? std::to_string(*version) : "missing", kSessionFormatVersion));
}

/// The recorded run's gyros: each [[slot]] serial the configuration's default does not name
/// (given at start: daemon/run_gyros.hpp).
std::vector<SlotGyro> recorded_gyros(const toml::table& t, const StationConfig& config) {
  std::vector<SlotGyro> out;
  const auto* list = t["slot"].as_array();
  for (std::size_t i = 0; list != nullptr && i < list->size() && i < config.slots.size(); ++i) {
    const auto* slot = (*list)[i].as_table();
    const auto serial = slot ? (*slot)["serial"].value<std::string>() : std::nullopt;
    if (serial && *serial != config.slots[i].serial)
      out.push_back({static_cast<int>(i + 1), *serial, ""});
  }
  return out;
}

RecordedSession read_session(const std::string& path, const toml::table& t) {
  const auto config = parse_station_config(required_text(t, path, "config"), path + "[config]");
  return {with_gyros(config, recorded_gyros(t, config)),
          parse_protocol(required_text(t, path, "protocol"), path + "[protocol]"),
          t["sim_seed"].value<std::int64_t>(), read_session_end(path),
          t["started_utc"].value<std::string>().value_or("")};
}

std::string fresh_db_path(const ReplayOptions& o) {
  if (!o.db.empty()) {
    if (fs::exists(o.db))
      throw InputError(fmt::format("{}: exists; --db names a new file for the replayed run", o.db));
    return o.db;
  }
  static std::atomic<int> n{0};
  // The replayed database is thrown away: on tmpfs when there is one (no disk writes at all).
  std::error_code ec;
  const fs::path dir = fs::is_directory("/dev/shm", ec) && access("/dev/shm", W_OK) == 0
                           ? fs::path("/dev/shm")
                           : fs::temp_directory_path();
  return (dir / fmt::format("station-replay-{}-{}.db", getpid(), n++)).string();
}

/// The report of a session whose files are not what its digest says.
ReplayReport not_the_recording(const DigestMismatch& m) {
  ReplayReport r;
  r.same = false;
  nlohmann::json at{{"file", m.file}};
  if (m.line) at["line"] = *m.line;
  r.first_difference = {{"at", at}, {"quantity", "digest"}, {"recorded", m.what}};
  r.notes.push_back(m.message());
  return r;
}

ReplayReport header_differs(const std::string& header_path, const nlohmann::json& d) {
  ReplayReport r;
  r.same = false;
  r.first_difference = d;
  r.notes.push_back(fmt::format("{}: key '{}': not what its config and protocol say", header_path,
                                d["at"]["key"].get<std::string>()));
  return r;
}

ReplayReport replay_and_compare(const ReplayOptions& o, const RecordedSession& session,
                                const std::string& result_path, SessionReads& reads) {
  const std::string db = fresh_db_path(o);
  ReplayReport report;
  {
    Store store(db);
    store.set_ticks_per_commit(600);  // nothing to lose: the recording is the record
    // A thrown-away database needs no write-ahead log and no syncs (the store's WAL writes each
    // page twice); its rollback journal stays (in memory), as a killed daemon's lost batch is
    // rolled back (Store::discard). The daemon's statements are the production ones.
    if (o.db.empty()) store.db().exec("PRAGMA journal_mode=MEMORY; PRAGMA synchronous=OFF;");
    std::optional<ReplayNarration> narration;
    if (o.narrate) narration.emplace(session.started_utc, session.end.last_tick_s);
    const std::int64_t run_id =
        replay_daemons(o.dir, reads, session, store, report, [&](double t_s) {
          if (narration) narration->at(t_s);
        });
    if (run_id != 0) {
      store.flush();
      report = compare_with_store(result_path, reads.reader("result.json"), store, run_id, o.rtol,
                                  o.atol);
    }
  }
  if (o.db.empty()) {
    std::error_code ec;
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(db + suffix, ec);
  }
  return report;
}

/// The replay, then what it did not read of each file: a file that is not what its digest says
/// is the finding, whatever the replay made of it (a changed line may have diverged it, or been
/// malformed), as when every file was checked before the replay.
ReplayReport replay_verified(const ReplayOptions& o, const RecordedSession& session,
                             const std::string& result_path, SessionReads& reads) {
  ReplayReport report;
  try {
    report = replay_and_compare(o, session, result_path, reads);
  } catch (const std::exception&) {
    if (auto m = reads.check_rest()) return not_the_recording(*m);
    throw;
  }
  if (auto m = reads.check_rest()) return not_the_recording(*m);
  return report;
}

}  // namespace

ReplayReport replay_session(const ReplayOptions& o) {
  if (!(o.rtol >= 0) || !(o.atol >= 0) || !std::isfinite(o.rtol) || !std::isfinite(o.atol))
    throw InputError(
        fmt::format("--rtol {} --atol {}: tolerances are finite and not negative", o.rtol, o.atol));
  const fs::path dir(o.dir);
  const std::string header_path = (dir / "session.toml").string();
  if (!fs::exists(header_path))
    throw InputError(fmt::format("{}: no such file (not a session)", header_path));
  const std::string result_path = (dir / "result.json").string();
  if (!fs::exists(result_path) && !fs::exists(result_path + ".gz"))
    throw InputError(fmt::format("{}: cannot open (the run did not end?)", result_path));
  // The recording is the one the run made before anything in it is read for its meaning: a
  // changed byte anywhere, session.toml included, is a difference naming file and line: digest.txt
  // and session.toml first, every other file as the replay reads it (one read of each). Without a
  // digest, the version says first why (version 2 wrote none).
  const bool has_digest = fs::exists(dir / "digest.txt") || fs::exists(dir / "digest.txt.gz");
  SessionReads reads(o.dir, o.verify && has_digest);
  if (auto m = reads.check_up_front()) return not_the_recording(*m);
  const toml::table header = parse_header(header_path);
  check_version(header_path, header);
  if (o.verify && !has_digest) {
    if (auto m = verify_session_digest(o.dir)) return not_the_recording(*m);
  }
  const RecordedSession session = read_session(header_path, header);
  if (auto d = header_difference(header_path, session.config, session.protocol)) {
    if (auto m = reads.check_rest()) return not_the_recording(*m);
    return header_differs(header_path, *d);
  }
  return replay_verified(o, session, result_path, reads);
}

}  // namespace station
