// Records a session (schemas/session.md): every exchange of every device, stamped on the run's
// clock, as line-oriented text in one directory: can.log (candump -l), modbus.log,
// ascii.log, gpio.log.
#pragma once

#include <atomic>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>

#include "drivers/common/tap.hpp"

namespace station {

/// A Tap writing the session's device logs. Thread-safe (the CAN and Modbus transports tap from
/// the sequencer's thread, GPIO edges may come from another).
class SessionRecorder final : public drivers::Tap {
 public:
  /// The time a record is logged at, seconds since the Unix epoch on the run's clock (the
  /// simulated clock under --sim); default: the record's own wall time.
  using Stamp = std::function<double(const drivers::TapRecord&)>;

  /// Opens can.log, modbus.log, ascii.log and gpio.log in `dir` (created if missing) for appending:
  /// a resumed run goes on in the same files. Throws InputError naming a path it cannot write.
  explicit SessionRecorder(const std::string& dir, Stamp stamp = {});
  void on_exchange(const drivers::TapRecord& record) noexcept override;
  /// Flushes the three logs (after each tick, so a kill loses at most one tick of log).
  void flush();
  /// While paused nothing is written: a resumed simulation replays its stored ticks to rebuild
  /// its state, and their exchanges are in the logs already.
  void pause(bool paused) { paused_ = paused; }

 private:
  void write_can(const drivers::TapRecord& record, double t_s);
  void write_line(std::ofstream& out, const drivers::TapRecord& record, double t_s);

  std::mutex mutex_;
  std::ofstream can_, modbus_, ascii_, gpio_;
  Stamp stamp_;
  std::atomic<bool> paused_{false};
};

/// The HEX field of a session log line: two lower-case digits per byte, "-" for none.
std::string hex_field(const std::vector<std::uint8_t>& bytes);

/// One line of modbus.log / gpio.log, without the newline:
/// "TIME DEVICE DIRECTION KIND HEX DETAIL" (HEX "-" when there are no bytes).
std::string format_session_line(const drivers::TapRecord& record, double t_s);

}  // namespace station
