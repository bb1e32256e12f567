// A recorded session's gpio.log as a GpioBank: reads answer what the lines read then, writes and
// the drained edges must be the recorded ones (else a ReplayDivergence). Its event fd is readable
// while the recording's next exchange is an edge, so a between-ticks wait (ReplayClock) sees it
// where the live daemon did.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "drivers/common/unique_fd.hpp"
#include "drivers/gpio/gpio_bank.hpp"
#include "station/session/replay_feed.hpp"
#include "station/session/session_log.hpp"

namespace station {

class ReplayGpioBank final : public drivers::gpio::GpioBank {
 public:
  /// `syncs_logged_by(t_s)`: how many of the recording's SYNC frames (ticks) are stamped at or
  /// before t_s, and `syncs_sent` how many the replay has sent: an edge is offered between ticks
  /// only when the recording drained it before the next tick's SYNC.
  ReplayGpioBank(drivers::gpio::GpioConfig config, ReplayFeed<SessionLogLine> lines,
                 std::function<std::size_t(double)> syncs_logged_by,
                 std::function<std::size_t()> syncs_sent);
  drivers::Result<void> open() override;
  drivers::Result<bool> read(std::string_view role) override;
  drivers::Result<void> write(std::string_view role, bool active) override;
  drivers::Result<void> apply_safe_state() override;
  void close() override;
  int event_fd() const override { return efd_.get(); }
  drivers::Result<std::vector<drivers::gpio::GpioEdge>> read_events() override;
  void set_tap(drivers::Tap*) override {}
  const drivers::gpio::GpioConfig& config() const override { return config_; }
  /// Exchanges not replayed yet.
  std::size_t remaining() { return lines_.remaining(); }
  /// The exchanges replayed so far (a resumed simulation asks them again).
  const std::vector<SessionLogLine>& consumed() const { return lines_.consumed(); }

 private:
  const SessionLogLine& expect(const char* kind, std::string_view role, const std::string& asked);
  void signal();  ///< the event fd readable iff the next exchange is an edge

  drivers::gpio::GpioConfig config_;
  ReplayFeed<SessionLogLine> lines_;
  drivers::UniqueFd efd_;
  bool readable_ = false;  ///< what the event fd holds (only this bank reads or writes it)
  bool open_ = false;
  std::function<std::size_t(double)> syncs_logged_by_;
  std::function<std::size_t()> syncs_sent_;
};

}  // namespace station
