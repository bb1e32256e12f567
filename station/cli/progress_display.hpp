// Progress of a run where the operator looks: one redrawn line on a terminal, a line every few
// minutes in a log, and systemd's status line (STATUS= through sd_notify) under a service.
#pragma once

#include <cstdio>
#include <functional>
#include <optional>
#include <string>

#include "compensation/binning.hpp"
#include "station/daemon/sequencer.hpp"

namespace station {

class ProgressDisplay {
 public:
  /// Bins are counted as recorded 1 s ticks per `bin_s` (this daemon's count: a resumed run
  /// starts again at 0). `out` gets the progress (a terminal: redrawn each tick; otherwise a line
  /// every `log_interval_s` of run time); `status` (may be empty) gets the same text every tick.
  ProgressDisplay(std::FILE* out, bool terminal, double log_interval_s, double bin_s,
                  std::function<void(const std::string&)> status);

  void tick(const TickReport& r);
  /// Ends a redrawn line (before other output or at the end of the run).
  void finish();

  /// The progress text of a tick: step, the time left (daemon/time_left.hpp), the step's
  /// label, run time, air and setpoint, bins so far.
  static std::string text(const TickReport& r, long bins, double bin_s = compensation::kPaperBinS);

 private:
  std::FILE* out_;
  bool terminal_;
  double log_interval_s_, bin_s_, next_log_s_ = 0;
  std::function<void(const std::string&)> status_;
  long recorded_ticks_ = 0;
  std::optional<double> left_before_hold_s_;  ///< the time left when a safe hold began
  bool line_open_ = false;
};

/// Sends `line` as systemd's status line (STATUS= through sd_notify; nothing outside systemd).
void notify_status(const std::string& line);

/// Chains progress (and, under systemd, STATUS=) onto the sequencer's on_tick.
void attach_progress(SequencerOptions& so, ProgressDisplay& progress);

}  // namespace station
