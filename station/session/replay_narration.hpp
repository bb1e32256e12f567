// What `station replay DIR` says while it replays: the replayed daemon's log lines are the
// recording's, not news, so each reads "replayed, recorded 2026-11-23T06:10:00Z" (the session's
// start plus the run's time of the tick) where a live line has the wall time; and a long replay
// shows how far it is (issue 35). Both go to stderr only: the comparison and its digest never
// see them.
#pragma once

#include <atomic>
#include <cstdio>
#include <memory>
#include <string>

namespace station {

/// "2026-11-23T06:00:00Z" plus `t_s` (whole seconds), in the same form; "at t = N s" when
/// `started_utc` is empty; throws InputError when it is not that form or not a date and time.
std::string utc_plus(const std::string& started_utc, double t_s);

/// While alive, every registered logger's lines read "replayed, recorded TIME LEVEL [NAME] ..."
/// (TIME: the session's start plus the tick's t_s); a progress line goes to `progress` at each
/// tenth of the recorded run. Not thread-safe beyond the logging itself: one replay at a time.
class ReplayNarration {
 public:
  /// `started_utc`: session.toml's started_utc; `last_tick_s`: its [end] last_tick_s. A missing
  /// or malformed started_utc is said once on `progress`; the lines then carry the run time.
  ReplayNarration(std::string started_utc, double last_tick_s, std::FILE* progress = stderr);
  ~ReplayNarration();
  ReplayNarration(const ReplayNarration&) = delete;
  ReplayNarration& operator=(const ReplayNarration&) = delete;

  /// The replay reached the tick at `t_s` of the run (before it runs).
  void at(double t_s);

  struct Stamp;  ///< the session's start and the tick's t, shared with the log formatter

 private:
  std::shared_ptr<Stamp> stamp_;
  double last_tick_s_;
  int tenths_shown_ = 0;
  std::FILE* progress_;
};

}  // namespace station
