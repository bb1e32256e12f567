// The recorded daemons of a session, one after the other, through the one host (see
// replay_daemons.hpp): each device answered from the session's logs.
#include "station/session/replay_daemons.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <deque>
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
#include "station/session/replay_feed.hpp"
#include "station/session/replay_gpio.hpp"
#include "station/session/replay_modbus.hpp"
#include "station/session/session_log.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;
namespace dr = station::drivers;

/// The session's logs, each read once from its start to its end as the replayed daemons ask.
struct SessionLogs {
  CanLogStream can;
  SessionLogStream modbus, gpio;
  std::optional<SessionLogStream> ascii;  // absent before issue 20
  std::int64_t can_records = 0;           // records taken from `can`

  SessionLogs(const std::string& dir, SessionReads& reads)
      : can(reads.reader("can.log")),
        modbus(reads.reader("modbus.log")),
        gpio(reads.reader("gpio.log")) {
    const auto ascii_log = fs::path(dir) / "ascii.log";
    if (fs::exists(ascii_log) || fs::exists(ascii_log.string() + ".gz"))
      ascii.emplace(reads.reader("ascii.log"));
  }
};

/// The lines [from, to) of `log` (1-based line numbers as the file counts them), pulled one at a
/// time: what one daemon's life answers from.
ReplayFeed<SessionLogLine>::Pull lines_between(SessionLogStream* log, std::int64_t from,
                                               std::int64_t to) {
  return [log, from, to](SessionLogLine& out) {
    if (log == nullptr) return false;
    while (log->peek() != nullptr && log->peek()->line_no < from) (void)log->take();
    if (log->peek() == nullptr || log->peek()->line_no >= to) return false;
    out = log->take();
    return true;
  };
}

/// One log of several devices (modbus.log, ascii.log) split by device as each asks: the lines of
/// the others read on the way wait for theirs (a tick's worth: the daemon asks in log order).
class DeviceSplit {
 public:
  explicit DeviceSplit(ReplayFeed<SessionLogLine> lines) : lines_(std::move(lines)) {}
  ReplayFeed<SessionLogLine>::Pull of(const std::string& device) {
    return [this, device](SessionLogLine& out) {
      auto& mine = waiting_[device];
      while (mine.empty()) {
        if (lines_.peek() == nullptr) return false;
        SessionLogLine l = lines_.take();
        if (l.device == device) {
          out = std::move(l);
          return true;
        }
        waiting_[l.device].push_back(std::move(l));
      }
      out = std::move(mine.front());
      mine.pop_front();
      return true;
    };
  }

 private:
  ReplayFeed<SessionLogLine> lines_;
  std::map<std::string, std::deque<SessionLogLine>> waiting_;
};

/// The replay transports of every device for one daemon's life (one segment of a session: the
/// whole run, or the part before a kill, or after a resume), each pulling its lines from the logs.
struct ReplayRig {
  DeviceSplit modbus, ascii;
  ReplayFeed<SessionLogLine> gpio;
  std::shared_ptr<ReplayFeed<dr::can::CandumpRecord>> can;
  std::vector<double> sync_times_s;  ///< of the SYNC frames read from the CAN log so far
  bool keep;                         ///< keep what was replayed (a resumed simulation asks again)
  std::map<std::string, const RecordedModbusWire*> wires;
  std::map<std::string, const RecordedLineWire*> line_wires;
  const ReplayCanTransport* can_transport = nullptr;
  const ReplayGpioBank* gpio_bank = nullptr;

  ReplayRig(ReplayFeed<SessionLogLine> modbus_lines, ReplayFeed<SessionLogLine> ascii_lines,
            ReplayFeed<SessionLogLine> gpio_lines, std::vector<dr::can::CandumpRecord> can_prefix,
            ReplayFeed<dr::can::CandumpRecord>::Pull can_pull, bool keep_consumed)
      : modbus(std::move(modbus_lines)),
        ascii(std::move(ascii_lines)),
        gpio(std::move(gpio_lines)),
        keep(keep_consumed) {
    for (const auto& r : can_prefix) note_sync(r);
    can = std::make_shared<ReplayFeed<dr::can::CandumpRecord>>(
        std::move(can_prefix),
        [this, pull = std::move(can_pull)](dr::can::CandumpRecord& r) {
          if (!pull(r)) return false;
          note_sync(r);
          return true;
        },
        keep);
  }
  ReplayRig(const ReplayRig&) = delete;
  ReplayRig& operator=(const ReplayRig&) = delete;

  void note_sync(const dr::can::CandumpRecord& r) {
    if (is_sync_frame(r.frame))
      sync_times_s.push_back(static_cast<double>(r.time_sec) + 1e-6 * r.time_usec);
  }
  /// The SYNC frames of this life's CAN log stamped at or before `t_s` (read ahead to the first
  /// after it).
  std::size_t syncs_logged_by(double t_s) {
    while ((sync_times_s.empty() || sync_times_s.back() <= t_s) &&
           can->peek(can->read_ahead()) != nullptr) {
    }
    return static_cast<std::size_t>(
        std::upper_bound(sync_times_s.begin(), sync_times_s.end(), t_s) - sync_times_s.begin());
  }
  RigOptions options(const dr::Clock& clock) {
    RigOptions o;
    o.clock = &clock;
    o.modbus_wire_factory = [this](const std::string& device, const dr::modbus::Endpoint&) {
      // Each factory runs once per device: its lines go to its transport as it asks.
      auto w = std::make_unique<RecordedModbusWire>(
          device, ReplayFeed<SessionLogLine>({}, modbus.of(device), keep));
      wires[device] = w.get();
      return w;
    };
    o.line_wire_factory = [this](const std::string& device, const dr::ascii::LineEndpoint&) {
      auto w = std::make_unique<RecordedLineWire>(
          device, ReplayFeed<SessionLogLine>({}, ascii.of(device), keep));
      line_wires[device] = w.get();
      return w;
    };
    o.can_transport_factory = [this] {
      auto t = std::make_unique<ReplayCanTransport>(can);
      can_transport = t.get();
      return t;
    };
    o.replayed_can = true;
    o.gpio_factory = [this](const dr::gpio::GpioConfig& g) {
      auto b = std::make_unique<ReplayGpioBank>(
          g, std::move(gpio), [this](double t_s) { return syncs_logged_by(t_s); },
          [this] {
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
      for (const auto& l : wire->consumed()) modbus_out.push_back(l);
    for (const auto& [device, wire] : line_wires)
      for (const auto& l : wire->consumed()) ascii_out.push_back(l);
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
  DaemonReplay(const std::string& dir, SessionReads& reads, const RecordedSession& session,
               Store& store, ReplayReport& report, std::function<void(double)> on_tick)
      : dir_(dir),
        session_(session),
        store_(store),
        report_(report),
        on_tick_(std::move(on_tick)),
        resumes_(replayable_resumes(dir, session)),
        logs_(dir, reads) {}

  /// The run's id, 0 when a divergence ended it (reported in the report).
  std::int64_t run() {
    for (std::size_t k = 0; k <= resumes_.size(); ++k) {
      const auto devices = take(k < resumes_.size() ? &resumes_[k] : nullptr);
      if (const auto id = segment(k, *devices)) return *id;
    }
    return 0;
  }

 private:
  /// The recorded devices of daemon k, which ran until `killed` (nullptr: to the end).
  std::unique_ptr<ReplayRig> take(const SessionResume* killed) {
    const auto end = [killed](std::int64_t lines) {
      return killed ? lines + 1 : std::numeric_limits<std::int64_t>::max();
    };
    // A resumed simulation's daemon asks what the killed one replayed again: kept only then.
    const bool keep = !resumes_.empty() && session_.sim_seed.has_value();
    // Modbus and ASCII lines are kept by each device's feed, GPIO's by its one.
    auto feed = [&](std::vector<SessionLogLine>& prefix, SessionLogStream* log, std::int64_t from,
                    std::int64_t lines, bool keep_here = false) {
      return ReplayFeed<SessionLogLine>(std::move(prefix), lines_between(log, from, end(lines)),
                                        keep_here);
    };
    const std::int64_t can_to =
        killed ? killed->can_lines : std::numeric_limits<std::int64_t>::max();
    auto can_pull = [this, from = can_from_, can_to](dr::can::CandumpRecord& r) {
      for (; logs_.can_records < can_to; ++logs_.can_records) {
        if (!logs_.can.next(r)) return false;
        if (logs_.can_records >= from) return ++logs_.can_records, true;
      }
      return false;
    };
    auto rig = std::make_unique<ReplayRig>(
        feed(modbus_prefix_, &logs_.modbus, modbus_from_, killed ? killed->modbus_lines : 0),
        feed(ascii_prefix_, logs_.ascii ? &*logs_.ascii : nullptr, ascii_from_,
             killed ? killed->ascii_lines : 0),
        feed(gpio_prefix_, &logs_.gpio, gpio_from_, killed ? killed->gpio_lines : 0, keep),
        std::move(can_prefix_), can_pull, keep);
    modbus_prefix_.clear();
    ascii_prefix_.clear();
    gpio_prefix_.clear();
    can_prefix_.clear();
    if (killed) {
      modbus_from_ = killed->modbus_lines + 1;
      ascii_from_ = killed->ascii_lines + 1;
      gpio_from_ = killed->gpio_lines + 1;
      can_from_ = killed->can_lines;
    }
    return rig;
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

std::int64_t replay_daemons(const std::string& dir, SessionReads& reads,
                            const RecordedSession& session, Store& store, ReplayReport& report,
                            const std::function<void(double t_s)>& on_tick) {
  return DaemonReplay(dir, reads, session, store, report, on_tick).run();
}

}  // namespace station
