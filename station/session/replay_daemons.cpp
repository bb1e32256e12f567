// The recorded daemons of a session, one after the other, through the one host (see
// replay_daemons.hpp): each device answered from the session's logs.
#include "station/session/replay_daemons.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <future>
#include <limits>
#include <map>

#include "drivers/can/candump_log.hpp"
#include "station/common/input_error.hpp"
#include "station/daemon/host.hpp"
#include "station/daemon/rig.hpp"
#include "station/session/replay_ascii.hpp"
#include "station/session/replay_can.hpp"
#include "station/session/replay_clock.hpp"
#include "station/session/replay_gpio.hpp"
#include "station/session/replay_modbus.hpp"
#include "station/session/session_log.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;
namespace dr = station::drivers;

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
  const ReplayCanTransport* can_transport = nullptr;
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
      auto t = std::make_unique<ReplayCanTransport>(std::move(can));
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
std::vector<SessionResume> replayable_resumes(const std::string& dir,
                                              const RecordedSession& session) {
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
  // Nothing logged before the first resume is a recording begun by a resumed daemon, unless
  // the first daemon was killed before it committed anything (after_tick_s = -1).
  if (first.after_tick_s >= 0 &&
      first.can_lines + first.modbus_lines + first.ascii_lines + first.gpio_lines == 0)
    throw InputError(
        fmt::format("{}: the recording starts with a resumed run (after t = {:.0f} "
                    "s); its first part was not recorded",
                    path, first.after_tick_s));
  return resumes;
}

/// The session's daemons replayed one after the other into one store.
class DaemonReplay {
 public:
  DaemonReplay(const std::string& dir, const RecordedSession& session, Store& store,
               ReplayReport& report, std::function<void(double)> on_tick)
      : dir_(dir),
        session_(session),
        store_(store),
        report_(report),
        on_tick_(std::move(on_tick)),
        resumes_(replayable_resumes(dir, session)),
        logs_(dir) {}

  /// The run's id, 0 when a divergence ended it (reported in the report).
  std::int64_t run() {
    for (std::size_t k = 0; k <= resumes_.size(); ++k) {
      ReplayRig devices = take(k < resumes_.size() ? &resumes_[k] : nullptr);
      if (const auto id = segment(k, devices)) return *id;
    }
    return 0;
  }

 private:
  /// The recorded devices of daemon k, which ran until `killed` (nullptr: to the end).
  ReplayRig take(const SessionResume* killed) {
    const auto end = [killed](std::int64_t lines) {
      return killed ? lines + 1 : std::numeric_limits<std::int64_t>::max();
    };
    std::vector<SessionLogLine> modbus = std::move(modbus_prefix_), gpio = std::move(gpio_prefix_);
    std::vector<SessionLogLine> ascii = std::move(ascii_prefix_);
    take_lines(logs_.modbus, modbus_from_, end(killed ? killed->modbus_lines : 0), modbus);
    take_lines(logs_.ascii, ascii_from_, end(killed ? killed->ascii_lines : 0), ascii);
    take_lines(logs_.gpio, gpio_from_, end(killed ? killed->gpio_lines : 0), gpio);
    std::vector<dr::can::CandumpRecord> can = std::move(can_prefix_);
    const auto can_to = killed ? std::min<std::size_t>(static_cast<std::size_t>(killed->can_lines),
                                                       logs_.can.size())
                               : logs_.can.size();
    if (can.empty() && can_from_ == 0 && can_to == logs_.can.size()) {
      can = std::move(logs_.can);
      logs_.can.clear();
    } else {
      can.reserve(can.size() + (can_to - static_cast<std::size_t>(can_from_)));
      for (auto i = static_cast<std::size_t>(can_from_); i < can_to; ++i)
        can.push_back(std::move(logs_.can[i]));
    }
    if (killed) {
      modbus_from_ = killed->modbus_lines + 1;
      ascii_from_ = killed->ascii_lines + 1;
      gpio_from_ = killed->gpio_lines + 1;
      can_from_ = static_cast<std::int64_t>(can_to);
    }
    return ReplayRig(std::move(modbus), std::move(ascii), std::move(gpio), std::move(can));
  }

  /// Daemon k's life: the run's id when it ended the run, 0 on a divergence, nullopt when it
  /// was killed where the recording says.
  std::optional<std::int64_t> segment(std::size_t k, ReplayRig& devices) {
    const bool killed = k < resumes_.size();
    ReplayClock clock;
    Rig rig = build_rig(session_.config, devices.options(clock));
    Host host(session_.config, rig, store_, clock);
    const StartPlan plan = host.start({session_.protocol, false, session_.sim_seed, {}});
    if (k > 0 && !plan.resume)
      throw InputError(fmt::format("{}: resume {}: no run to resume", dir_, k));
    SequencerOptions so;
    so.sim_seed = session_.sim_seed;
    // A rig's restarted daemon continued where the wall clock was when it came back.
    if (k > 0 && !session_.sim_seed) so.resume_at_t_s = resumes_[k - 1].next_tick_s;
    // The operator's stop or abort (session.toml [end]) takes effect after the tick it did.
    std::atomic<bool> stop{false}, abort{false};
    so.stop = &stop;
    so.abort = &abort;
    so.on_tick = [&](const TickReport& r) { after_tick(r.t_s, k, devices, stop, abort); };
    // A daemon killed before it sent its first SYNC ends before its first tick here too.
    const bool killed_first = killed && resumes_[k].after_tick_s < 0 && !sent_a_sync(k);
    so.before_tick = [this, killed_first](double t_s) {
      if (killed_first) throw KilledHere{};
      if (on_tick_) on_tick_(t_s);
    };
    try {
      const auto out = host.run(plan, std::move(so));
      if (!killed) return out.run_id;
      throw InputError(fmt::format("{}: the run ended before its recorded kill at t = {:.0f} s",
                                   dir_, resumes_[k].after_tick_s));
    } catch (const KilledHere&) {
      return std::nullopt;
    } catch (const ReplayDivergence& d) {
      diverged(d);
      return 0;
    }
  }

  /// Whether daemon k's part of the CAN log holds a frame (it began a tick).
  bool sent_a_sync(std::size_t k) const {
    const std::int64_t from = k > 0 ? resumes_[k - 1].can_lines : 0;
    return resumes_[k].can_lines > from;
  }

  /// Ends daemon k's life where the recording says: the operator's stop or abort after the
  /// tick it came, or the kill (KilledHere) after the last tick the killed daemon committed.
  void after_tick(double t_s, std::size_t k, ReplayRig& devices, std::atomic<bool>& stop,
                  std::atomic<bool>& abort) {
    last_tick_s_ = t_s;
    const bool killed = k < resumes_.size();
    if (!killed && t_s >= session_.end.last_tick_s) {
      stop = session_.end.state == to_string(RunState::stopped);
      abort = session_.end.state == to_string(RunState::aborted);
    }
    if (!killed || t_s < resumes_[k].after_tick_s) return;
    // A killed daemon that had committed no tick (after_tick_s = -1; a simulation commits in
    // batches) left nothing for the next to pass over: its batch is rolled back (the events of
    // the tick before its first sample stay, as they did) and the resumed simulation's
    // recording starts at t = 0 with nothing replayed again.
    if (resumes_[k].after_tick_s < 0) {
      store_.discard();
      throw KilledHere{};
    }
    store_.flush();  // what the killed daemon had committed
    // A resumed simulation asks what this life replayed again, first.
    if (session_.sim_seed)
      devices.consumed(modbus_prefix_, ascii_prefix_, gpio_prefix_, can_prefix_);
    throw KilledHere{};
  }

  void diverged(const ReplayDivergence& d) {
    report_.same = false;
    report_.first_difference = {{"at", {{"tick", last_tick_s_ + 1}, {"device", d.device}}},
                                {"quantity", "request"},
                                {"recorded", d.recorded},
                                {"replayed", d.asked}};
    report_.notes.push_back(
        fmt::format("diverged at tick t = {:.0f} s: {}", last_tick_s_ + 1, d.what()));
    report_.ticks = static_cast<std::int64_t>(last_tick_s_ + 1);
  }

  const std::string dir_;
  const RecordedSession& session_;
  Store& store_;
  ReplayReport& report_;
  const std::function<void(double)> on_tick_;
  const std::vector<SessionResume> resumes_;
  SessionLogs logs_;
  // The part of the recording a segment's daemon asks first: a resumed simulation recomputes
  // its stored ticks through the devices, with the recorder paused.
  std::vector<SessionLogLine> modbus_prefix_, ascii_prefix_, gpio_prefix_;
  std::vector<dr::can::CandumpRecord> can_prefix_;
  std::int64_t modbus_from_ = 1, ascii_from_ = 1, gpio_from_ = 1, can_from_ = 0;
  double last_tick_s_ = -1;
};

}  // namespace

std::int64_t replay_daemons(const std::string& dir, const RecordedSession& session, Store& store,
                            ReplayReport& report, const std::function<void(double t_s)>& on_tick) {
  return DaemonReplay(dir, session, store, report, on_tick).run();
}

}  // namespace station
