// Replaying a session directory through the daemon (see session_replay.hpp).
#include "station/session/session_replay.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>

#include "drivers/can/candump_log.hpp"
#include "drivers/can/replay_transport.hpp"
#include "station/common/input_error.hpp"
#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/daemon/rig.hpp"
#include "station/daemon/sequencer.hpp"
#include "station/session/replay_clock.hpp"
#include "station/session/replay_gpio.hpp"
#include "station/session/replay_modbus.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_log.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;
namespace dr = station::drivers;

/// What session.toml says the run was.
struct Session {
  StationConfig config;
  Protocol protocol;
  std::optional<std::int64_t> sim_seed;
};

std::string required_text(const toml::table& t, const std::string& path, const char* key) {
  const auto v = t[key].value<std::string>();
  if (!v) throw InputError(fmt::format("{}: key '{}': missing or not a string", path, key));
  return *v;
}

Session read_header(const std::string& dir) {
  const std::string path = (fs::path(dir) / "session.toml").string();
  if (!fs::exists(path)) throw InputError(fmt::format("{}: no such file (not a session)", path));
  toml::table t;
  try {
    t = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: {}", path, e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
  const auto version = t["format_version"].value<std::int64_t>();
  if (version != kSessionFormatVersion) {
    throw InputError(
        fmt::format("{}: key 'format_version': {} is not a version this station "
                    "reads ({})",
                    path, version ? std::to_string(*version) : "missing", kSessionFormatVersion));
  }
  Session s{parse_station_config(required_text(t, path, "config"), path + "[config]"),
            parse_protocol(required_text(t, path, "protocol"), path + "[protocol]"),
            t["sim_seed"].value<std::int64_t>()};
  return s;
}

std::string fresh_db_path(const ReplayOptions& o) {
  if (!o.db.empty()) {
    if (fs::exists(o.db))
      throw InputError(fmt::format("{}: exists; --db names a new file for the replayed run", o.db));
    return o.db;
  }
  static std::atomic<int> n{0};
  return (fs::temp_directory_path() / fmt::format("station-replay-{}-{}.db", getpid(), n++))
      .string();
}

/// The replay transports of every device, from the session's logs.
struct ReplayRig {
  std::map<std::string, std::vector<SessionLogLine>> modbus;  ///< by device
  std::vector<SessionLogLine> gpio;
  std::vector<dr::can::CandumpRecord> can;
  std::vector<double> sync_times_s;
  const dr::can::ReplayCanTransport* can_transport = nullptr;

  explicit ReplayRig(const std::string& dir) {
    // The CAN log is read on a second thread while the Modbus and GPIO logs are read here: the
    // files are independent, and reading them is most of a long replay's set-up.
    auto can_log = std::async(std::launch::async, [path = (fs::path(dir) / "can.log").string()] {
      return read_session_can_log(path);
    });
    std::vector<SessionLogLine>* to = nullptr;  // the last line's device's (lines come in runs)
    read_session_log((fs::path(dir) / "modbus.log").string(), [&](SessionLogLine&& l) {
      if (to == nullptr || to->back().device != l.device) to = &modbus[l.device];
      to->push_back(std::move(l));
    });
    gpio = read_session_log((fs::path(dir) / "gpio.log").string());
    can = can_log.get();  // rethrows the reader's InputError
    for (const auto& r : can)
      if ((r.frame.can_id & CAN_EFF_MASK) == 0x080)  // SYNC (schemas/can_frames.md)
        sync_times_s.push_back(static_cast<double>(r.time_sec) + 1e-6 * r.time_usec);
  }
  RigOptions options(const dr::Clock& clock) {
    RigOptions o;
    o.clock = &clock;
    o.modbus_wire_factory = [this](const std::string& device, const dr::modbus::Endpoint&) {
      // Each factory runs once per device: the recording moves into its transport.
      return std::make_unique<RecordedModbusWire>(device, std::move(modbus[device]));
    };
    o.can_transport_factory = [this] {
      auto t = std::make_unique<dr::can::ReplayCanTransport>(std::move(can));
      can_transport = t.get();
      return t;
    };
    o.replayed_can = true;
    o.gpio_factory = [this](const dr::gpio::GpioConfig& g) {
      return std::make_unique<ReplayGpioBank>(g, std::move(gpio), sync_times_s, [this] {
        return can_transport != nullptr ? can_transport->syncs_sent() : std::size_t{0};
      });
    };
    return o;
  }
};

}  // namespace

ReplayReport replay_session(const ReplayOptions& o) {
  const Session session = read_header(o.dir);
  const std::string result_path = (fs::path(o.dir) / "result.json").string();
  if (!fs::exists(result_path) && !fs::exists(result_path + ".gz"))
    throw InputError(fmt::format("{}: cannot open (the run did not end?)", result_path));
  ReplayRig devices(o.dir);
  ReplayClock clock;
  Rig rig = build_rig(session.config, devices.options(clock));
  const std::string db = fresh_db_path(o);
  ReplayReport report;
  {
    Store store(db);
    store.set_ticks_per_commit(600);  // nothing to lose: the recording is the record
    SequencerOptions so;
    so.sim_seed = session.sim_seed;
    double last_tick_s = -1;
    so.on_tick = [&last_tick_s](const TickReport& r) { last_tick_s = r.t_s; };
    std::int64_t run_id = 0;
    try {
      Sequencer seq(session.config, session.protocol, rig, store, clock, so);
      run_id = seq.run().run_id;
    } catch (const ReplayDivergence& d) {
      report.same = false;
      report.first_difference = {{"at", {{"tick", last_tick_s + 1}, {"device", d.device}}},
                                 {"quantity", "request"},
                                 {"recorded", d.recorded},
                                 {"replayed", d.asked}};
      report.notes.push_back(
          fmt::format("diverged at tick t = {:.0f} s: {}", last_tick_s + 1, d.what()));
      report.ticks = static_cast<std::int64_t>(last_tick_s + 1);
    }
    if (run_id != 0) {
      store.flush();
      report = compare_with_store(result_path, store, run_id, o.rtol, o.atol);
    }
  }
  if (o.db.empty()) {
    std::error_code ec;
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(db + suffix, ec);
  }
  return report;
}

}  // namespace station
