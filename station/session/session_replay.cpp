// Replaying a session directory through the daemon (see session_replay.hpp).
#include "station/session/session_replay.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <map>

#include "drivers/can/candump_log.hpp"
#include "drivers/can/replay_transport.hpp"
#include "station/common/input_error.hpp"
#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/daemon/resume.hpp"
#include "station/daemon/rig.hpp"
#include "station/daemon/sequencer.hpp"
#include "station/session/replay_ascii.hpp"
#include "station/session/replay_clock.hpp"
#include "station/session/replay_gpio.hpp"
#include "station/session/replay_modbus.hpp"
#include "station/session/session_digest.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_log.hpp"
#include "station/session/session_metadata.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;
namespace dr = station::drivers;

/// What session.toml says the run was.
struct Session {
  StationConfig config;
  Protocol protocol;
  std::optional<std::int64_t> sim_seed;
  SessionEnd end;
};

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

Session read_session(const std::string& path, const toml::table& t) {
  return {parse_station_config(required_text(t, path, "config"), path + "[config]"),
          parse_protocol(required_text(t, path, "protocol"), path + "[protocol]"),
          t["sim_seed"].value<std::int64_t>(), read_session_end(path)};
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

/// Everything the session's three logs hold, in order.
struct SessionLogs {
  std::vector<SessionLogLine> modbus, ascii, gpio;
  std::vector<dr::can::CandumpRecord> can;

  explicit SessionLogs(const std::string& dir) {
    // The CAN log is read on a second thread while the Modbus and GPIO logs are read here: the
    // files are independent, and reading them is most of a long replay's set-up.
    auto can_log = std::async(std::launch::async, [path = (fs::path(dir) / "can.log").string()] {
      return read_session_can_log(path);
    });
    modbus = read_session_log((fs::path(dir) / "modbus.log").string());
    const auto ascii_log = fs::path(dir) / "ascii.log";  // absent before issue 20
    if (fs::exists(ascii_log) || fs::exists(ascii_log.string() + ".gz"))
      ascii = read_session_log(ascii_log.string());
    gpio = read_session_log((fs::path(dir) / "gpio.log").string());
    can = can_log.get();  // rethrows the reader's InputError
  }
};

/// The lines [from, to) of a log (1-based line numbers as the file counts them) appended to
/// `out`, moved out of `lines`.
void take_lines(std::vector<SessionLogLine>& lines, std::int64_t from, std::int64_t to,
                std::vector<SessionLogLine>& out) {
  const bool all = lines.empty() || (lines.front().line_no >= from && lines.back().line_no < to);
  if (all && out.empty()) {  // a session without restarts: no copy at all
    out = std::move(lines);
    lines.clear();
    return;
  }
  for (auto& l : lines)
    if (l.line_no >= from && l.line_no < to) out.push_back(std::move(l));
}

/// The replay transports of every device for one daemon's life (one segment of a session: the
/// whole run, or the part before a kill, or after a resume).
struct ReplayRig {
  std::map<std::string, std::vector<SessionLogLine>> modbus;  ///< by device
  std::map<std::string, std::vector<SessionLogLine>> ascii;   ///< by device
  std::vector<SessionLogLine> gpio;
  std::vector<dr::can::CandumpRecord> can;
  std::vector<double> sync_times_s;
  std::map<std::string, const RecordedModbusWire*> wires;
  std::map<std::string, const RecordedLineWire*> line_wires;
  const dr::can::ReplayCanTransport* can_transport = nullptr;
  const ReplayGpioBank* gpio_bank = nullptr;

  ReplayRig(std::vector<SessionLogLine> modbus_lines, std::vector<SessionLogLine> ascii_lines,
            std::vector<SessionLogLine> gpio_lines, std::vector<dr::can::CandumpRecord> can_records)
      : gpio(std::move(gpio_lines)), can(std::move(can_records)) {
    for (const auto& [lines, by_device] :
         {std::pair{&modbus_lines, &modbus}, std::pair{&ascii_lines, &ascii}}) {
      std::vector<SessionLogLine>* to = nullptr;  // the last line's device's (lines come in runs)
      for (auto& l : *lines) {
        if (to == nullptr || to->back().device != l.device) to = &(*by_device)[l.device];
        to->push_back(std::move(l));
      }
    }
    for (const auto& r : can)
      if ((r.frame.can_id & CAN_EFF_MASK) == 0x080)  // SYNC (schemas/can_frames.md)
        sync_times_s.push_back(static_cast<double>(r.time_sec) + 1e-6 * r.time_usec);
  }
  RigOptions options(const dr::Clock& clock) {
    RigOptions o;
    o.clock = &clock;
    o.modbus_wire_factory = [this](const std::string& device, const dr::modbus::Endpoint&) {
      // Each factory runs once per device: the recording moves into its transport.
      auto w = std::make_unique<RecordedModbusWire>(device, std::move(modbus[device]));
      wires[device] = w.get();
      return w;
    };
    o.line_wire_factory = [this](const std::string& device, const dr::ascii::LineEndpoint&) {
      auto w = std::make_unique<RecordedLineWire>(device, std::move(ascii[device]));
      line_wires[device] = w.get();
      return w;
    };
    o.can_transport_factory = [this] {
      auto t = std::make_unique<dr::can::ReplayCanTransport>(std::move(can));
      can_transport = t.get();
      return t;
    };
    o.replayed_can = true;
    o.gpio_factory = [this](const dr::gpio::GpioConfig& g) {
      auto b = std::make_unique<ReplayGpioBank>(g, std::move(gpio), sync_times_s, [this] {
        return can_transport != nullptr ? can_transport->syncs_sent() : std::size_t{0};
      });
      gpio_bank = b.get();
      return b;
    };
    return o;
  }
  /// What this daemon's life replayed so far, in log order: a resumed simulation asks it again.
  void consumed(std::vector<SessionLogLine>& modbus_out, std::vector<SessionLogLine>& ascii_out,
                std::vector<SessionLogLine>& gpio_out,
                std::vector<dr::can::CandumpRecord>& can_out) const {
    for (const auto& [device, wire] : wires)
      for (auto& l : wire->consumed()) modbus_out.push_back(std::move(l));
    for (const auto& [device, wire] : line_wires)
      for (auto& l : wire->consumed()) ascii_out.push_back(std::move(l));
    for (auto* out : {&modbus_out, &ascii_out})
      std::sort(out->begin(), out->end(),
                [](const auto& a, const auto& b) { return a.line_no < b.line_no; });
    if (gpio_bank != nullptr) gpio_out = gpio_bank->consumed();
    if (can_transport != nullptr) can_out = can_transport->consumed();
  }
};

/// Thrown from the tick callback where the recorded daemon was killed.
struct KilledHere {};

/// The session's restarts (session.toml [[resume]]), checked for what replay can reproduce.
std::vector<SessionResume> replayable_resumes(const std::string& dir, const Session& session) {
  const std::string path = (fs::path(dir) / "session.toml").string();
  auto resumes = read_session_resumes(path);
  if (resumes.empty()) return resumes;
  for (std::size_t i = 0; i < resumes.size(); ++i)
    if (!session.sim_seed && !resumes[i].next_tick_s)
      throw InputError(
          fmt::format("{}: resume {}: key 'next_tick_s' missing: a rig's resumed "
                      "daemon chose its first tick from the wall clock",
                      path, i + 1));
  const auto& first = resumes.front();
  if (first.can_lines + first.modbus_lines + first.ascii_lines + first.gpio_lines == 0)
    throw InputError(
        fmt::format("{}: the recording starts with a resumed run (after t = {:.0f} "
                    "s); its first part was not recorded",
                    path, first.after_tick_s));
  return resumes;
}

/// Replays the session's daemons one after the other into `store` (one, or one per restart);
/// returns the run's id, 0 when a divergence ended it (reported in `report`).
std::int64_t replay_daemons(const ReplayOptions& o, const Session& session, Store& store,
                            ReplayReport& report) {
  const auto resumes = replayable_resumes(o.dir, session);
  SessionLogs logs(o.dir);
  // The part of the recording a segment's daemon asks first: a resumed simulation recomputes
  // its stored ticks through the devices, with the recorder paused.
  std::vector<SessionLogLine> modbus_prefix, ascii_prefix, gpio_prefix;
  std::vector<dr::can::CandumpRecord> can_prefix;
  std::int64_t modbus_from = 1, ascii_from = 1, gpio_from = 1, can_from = 0;
  double last_tick_s = -1;
  for (std::size_t k = 0; k <= resumes.size(); ++k) {
    const bool killed = k < resumes.size();
    const auto end = [killed](std::int64_t lines) {
      return killed ? lines + 1 : std::numeric_limits<std::int64_t>::max();
    };
    std::vector<SessionLogLine> modbus = std::move(modbus_prefix), gpio = std::move(gpio_prefix);
    take_lines(logs.modbus, modbus_from, end(killed ? resumes[k].modbus_lines : 0), modbus);
    std::vector<SessionLogLine> ascii = std::move(ascii_prefix);
    take_lines(logs.ascii, ascii_from, end(killed ? resumes[k].ascii_lines : 0), ascii);
    take_lines(logs.gpio, gpio_from, end(killed ? resumes[k].gpio_lines : 0), gpio);
    std::vector<dr::can::CandumpRecord> can = std::move(can_prefix);
    const auto can_to =
        killed
            ? std::min<std::size_t>(static_cast<std::size_t>(resumes[k].can_lines), logs.can.size())
            : logs.can.size();
    if (can.empty() && can_from == 0 && can_to == logs.can.size()) {
      can = std::move(logs.can);
      logs.can.clear();
    } else {
      can.reserve(can.size() + (can_to - static_cast<std::size_t>(can_from)));
      for (auto i = static_cast<std::size_t>(can_from); i < can_to; ++i)
        can.push_back(std::move(logs.can[i]));
    }
    if (killed) {
      modbus_from = resumes[k].modbus_lines + 1;
      ascii_from = resumes[k].ascii_lines + 1;
      gpio_from = resumes[k].gpio_lines + 1;
      can_from = static_cast<std::int64_t>(can_to);
    }
    ReplayRig devices(std::move(modbus), std::move(ascii), std::move(gpio), std::move(can));
    ReplayClock clock;
    Rig rig = build_rig(session.config, devices.options(clock));
    SequencerOptions so;
    so.sim_seed = session.sim_seed;
    std::optional<RunRecord> resume;
    if (k > 0) {
      resume = decide_resume(store, session.config, false, true).run;
      if (!resume) throw InputError(fmt::format("{}: resume {}: no run to resume", o.dir, k));
      if (session.sim_seed)  // a simulation recomputes its stored ticks from t = 0
        so.replay_until_t_s = resume->last_tick_s.value_or(-1.0);
      else  // a rig continued where the wall clock was when it came back
        so.resume_at_t_s = resumes[k - 1].next_tick_s;
    }
    // The operator's stop or abort (session.toml [end]) takes effect after the tick it did.
    std::atomic<bool> stop{false}, abort{false};
    so.stop = &stop;
    so.abort = &abort;
    so.on_tick = [&](const TickReport& r) {
      last_tick_s = r.t_s;
      if (!killed && r.t_s >= session.end.last_tick_s) {
        stop = session.end.state == to_string(RunState::stopped);
        abort = session.end.state == to_string(RunState::aborted);
      }
      if (!killed || r.t_s < resumes[k].after_tick_s) return;
      store.flush();  // what the killed daemon had committed
      if (session.sim_seed) devices.consumed(modbus_prefix, ascii_prefix, gpio_prefix, can_prefix);
      throw KilledHere{};
    };
    try {
      Sequencer seq(session.config, session.protocol, rig, store, clock, so);
      const auto out = seq.run(resume);
      if (!killed) return out.run_id;
      throw InputError(fmt::format("{}: the run ended before its recorded kill at t = {:.0f} s",
                                   o.dir, resumes[k].after_tick_s));
    } catch (const KilledHere&) {
      continue;
    } catch (const ReplayDivergence& d) {
      report.same = false;
      report.first_difference = {{"at", {{"tick", last_tick_s + 1}, {"device", d.device}}},
                                 {"quantity", "request"},
                                 {"recorded", d.recorded},
                                 {"replayed", d.asked}};
      report.notes.push_back(
          fmt::format("diverged at tick t = {:.0f} s: {}", last_tick_s + 1, d.what()));
      report.ticks = static_cast<std::int64_t>(last_tick_s + 1);
      return 0;
    }
  }
  return 0;
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

ReplayReport replay_and_compare(const ReplayOptions& o, const Session& session,
                                const std::string& result_path) {
  const std::string db = fresh_db_path(o);
  // result.json is parsed on another thread while the daemon replays.
  auto recorded =
      std::async(std::launch::async, [result_path] { return read_recorded_result(result_path); });
  ReplayReport report;
  {
    Store store(db);
    store.set_ticks_per_commit(600);  // nothing to lose: the recording is the record
    const std::int64_t run_id = replay_daemons(o, session, store, report);
    if (run_id != 0) {
      store.flush();
      report = compare_with_store(recorded.get(), result_path, store, run_id, o.rtol, o.atol);
    }
  }
  if (o.db.empty()) {
    std::error_code ec;
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(db + suffix, ec);
  }
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
  // changed byte anywhere, session.toml included, is a difference naming file and line. Without
  // a digest, the version says first why (version 2 wrote none).
  const bool has_digest = fs::exists(dir / "digest.txt") || fs::exists(dir / "digest.txt.gz");
  if (o.verify && has_digest) {
    if (auto m = verify_session_digest(o.dir)) return not_the_recording(*m);
  }
  const toml::table header = parse_header(header_path);
  check_version(header_path, header);
  if (o.verify && !has_digest) {
    if (auto m = verify_session_digest(o.dir)) return not_the_recording(*m);
  }
  const Session session = read_session(header_path, header);
  if (auto d = header_difference(header_path, session.config, session.protocol))
    return header_differs(header_path, *d);
  return replay_and_compare(o, session, result_path);
}

}  // namespace station
