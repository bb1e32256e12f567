// `run --record DIR` around one run: the device logs from the first exchange, the header when
// the run starts, a flush after every tick, result.json when it ends (schemas/session.md).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_recorder.hpp"
#include "station/store/store.hpp"

namespace station {

class SessionRecording {
 public:
  /// Opens the device logs in `dir`; `stamp` puts records on the run's clock. Throws InputError.
  SessionRecording(std::string dir, SessionRecorder::Stamp stamp = {})
      : dir_(std::move(dir)), recorder_(dir_, std::move(stamp)) {}

  /// The tap every transport of the rig writes to.
  SessionRecorder& tap() { return recorder_; }
  /// Writes session.toml (kept if it exists: a resumed run keeps its start's header).
  void start(const StationConfig& config, const Protocol& protocol, bool simulated,
             std::optional<std::int64_t> sim_seed);
  /// A resumed run marks its restart in the session (append_session_resume) before it logs
  /// anything: the last committed tick and the first tick of the resumed daemon
  /// (SequencerOptions::on_resume).
  void resumed(double after_tick_s, double next_tick_s) {
    recorder_.flush();
    append_session_resume(dir_, after_tick_s, next_tick_s);
  }
  /// After every tick: the logs reach the disk, so a kill loses at most one tick of log.
  void after_tick() { recorder_.flush(); }
  /// Ends the session: nothing more is logged; writes result.json from what the run stored,
  /// the [[end]] table (state, last tick) and digest.txt.
  void finish(Store& store, std::int64_t run_id);

  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  SessionRecorder recorder_;
};

}  // namespace station
