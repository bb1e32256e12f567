// Run progress on a terminal, in a log and in systemd's status line.
#include "station/cli/progress_display.hpp"

#include <fmt/format.h>
#include <systemd/sd-daemon.h>

#include <cmath>

#include "station/daemon/time_left.hpp"

namespace station {

ProgressDisplay::ProgressDisplay(std::FILE* out, bool terminal, double log_interval_s, double bin_s,
                                 std::function<void(const std::string&)> status)
    : out_(out),
      terminal_(terminal),
      log_interval_s_(log_interval_s),
      bin_s_(bin_s),
      status_(std::move(status)) {}

std::string ProgressDisplay::text(const TickReport& r, long bins, double bin_s) {
  std::string s = fmt::format("run {}  {:.2f} h  step {}/{}", r.run_id, r.t_s / 3600.0,
                              r.step_index + 1, r.steps);
  if (r.time_left_s) s += ", " + time_left_text(*r.time_left_s) + (r.step_label.empty() ? "" : ":");
  if (!r.step_label.empty()) s += " " + r.step_label;
  if (r.air_c && std::isfinite(*r.air_c)) s += fmt::format("  air {:.1f} C", *r.air_c);
  if (r.chamber) s += fmt::format("  setpoint {:.1f} C", r.chamber->setpoint_c);
  if (r.recording) s += fmt::format("  recording, {} bins of {:g} s", bins, bin_s);
  if (r.safe_hold) s += "  SAFE HOLD";
  return s;
}

void ProgressDisplay::tick(const TickReport& r) {
  if (r.replaying) return;
  if (r.recording) ++recorded_ticks_;
  const long bins = static_cast<long>(static_cast<double>(recorded_ticks_) / bin_s_);
  // A safe hold extends the run: the time left stands still while it lasts.
  if (!r.safe_hold) left_before_hold_s_ = r.time_left_s;
  std::string line;
  if (r.safe_hold && left_before_hold_s_ != r.time_left_s) {
    TickReport held = r;
    held.time_left_s = left_before_hold_s_;
    line = text(held, bins, bin_s_);
  } else {
    line = text(r, bins, bin_s_);
  }
  if (status_) status_(line);
  if (out_ == nullptr) return;
  if (terminal_) {
    // \r and erase-line: one line redrawn in place (ECMA-48 EL, CSI 2 K).
    fmt::print(out_, "\r\x1b[2K{}", line);
    std::fflush(out_);
    line_open_ = true;
  } else if (r.t_s >= next_log_s_) {
    next_log_s_ = r.t_s + log_interval_s_;
    fmt::print(out_, "{}\n", line);
    std::fflush(out_);
  }
}

void ProgressDisplay::finish() {
  if (line_open_ && out_ != nullptr) fmt::print(out_, "\n");
  line_open_ = false;
}

void notify_status(const std::string& line) {
  sd_notify(0, ("STATUS=" + line).c_str());
}

void attach_progress(SequencerOptions& so, ProgressDisplay& progress) {
  so.on_tick = [&progress, prev = so.on_tick](const TickReport& r) {
    if (prev) prev(r);
    progress.tick(r);
  };
}

}  // namespace station
