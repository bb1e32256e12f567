// A recorded session's ascii.log as a LineWire: the daemon's LineClient sends, the recording
// checks the bytes and answers with the recorded line, exchange by exchange. A reply read in
// parts (a frame's header, then its payload) is served from one recorded rx line in order. Sending
// anything else is a divergence (ReplayDivergence), as for Modbus (replay_modbus.hpp).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "drivers/ascii/line_wire.hpp"
#include "station/session/replay_feed.hpp"
#include "station/session/replay_modbus.hpp"
#include "station/session/session_log.hpp"

namespace station {

/// One line device's recorded exchanges (lines of ascii.log whose DEVICE is this device).
class RecordedLineWire final : public drivers::ascii::LineWire {
 public:
  RecordedLineWire(std::string device, std::vector<SessionLogLine> lines);
  /// The lines as the replay pulls them from ascii.log.
  RecordedLineWire(std::string device, ReplayFeed<SessionLogLine> lines);
  int open(double timeout_s) override;
  void close() override;
  int send(std::string_view bytes, double timeout_s) override;
  int receive(std::string& line, std::string_view terminator, double timeout_s,
              std::size_t max_bytes) override;
  int receive_exact(std::string& bytes, std::size_t n, double timeout_s) override;
  void flush() override {}
  std::size_t remaining() { return lines_.remaining(); }
  const std::vector<SessionLogLine>& consumed() const { return lines_.consumed(); }

 private:
  const SessionLogLine* peek() { return lines_.peek(); }
  /// The next line is a recorded failure whose message contains `what` (" send '", " reply to
  /// '", " connect "): consumed, errno set, true.
  bool recorded_error(std::string_view what);
  /// The next recorded reply, or what is left of the one being read: false and errno set for a
  /// recorded failure; throws ReplayDivergence when the log has no reply there.
  bool open_reply();

  std::string device_;
  ReplayFeed<SessionLogLine> lines_;
  std::string reply_;        // what is left of the reply being read in parts
  bool reply_open_ = false;  // a reply is being read in parts
};

}  // namespace station
