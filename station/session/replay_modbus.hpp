// A recorded session's modbus.log as a ModbusWire: the daemon's ModbusClient asks, the recording
// answers, exchange by exchange. Asking for anything else (another register, another value
// written) is a divergence: the code under replay no longer behaves as the recorded one.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/modbus/modbus_wire.hpp"
#include "station/session/replay_feed.hpp"
#include "station/session/session_log.hpp"

namespace station {

/// The first request a replay could not answer from its recording.
class ReplayDivergence : public std::runtime_error {
 public:
  ReplayDivergence(std::string device, std::string recorded, std::string asked, double t_s);
  std::string device, recorded, asked;
  double t_s;  ///< the recording's time at the point of divergence
};

/// One device's recorded exchanges (lines of modbus.log whose DEVICE is this device, in order).
class RecordedModbusWire final : public drivers::modbus::ModbusWire {
 public:
  RecordedModbusWire(std::string device, std::vector<SessionLogLine> lines);
  /// The lines as the replay pulls them from modbus.log.
  RecordedModbusWire(std::string device, ReplayFeed<SessionLogLine> lines);
  int open(double timeout_s) override;
  void close() override;
  int read(drivers::modbus::FunctionCode fc, int unit, std::uint16_t addr, int count,
           std::uint16_t* dest) override;
  int write(int unit, std::uint16_t addr, std::span<const std::uint16_t> words) override;
  void flush() override {}
  /// Exchanges not asked for yet (0 at the end of a faithful replay).
  std::size_t remaining() { return lines_.remaining(); }
  /// The exchanges replayed so far (a resumed simulation asks them again).
  const std::vector<SessionLogLine>& consumed() const { return lines_.consumed(); }

 private:
  /// Describes the daemon's request, for a divergence only.
  using Asked = std::function<std::string()>;
  /// The next line, which must be (direction, kind) and, when given, carry `bytes`; throws
  /// ReplayDivergence otherwise.
  const SessionLogLine& expect(const char* direction, const char* kind,
                               const std::vector<std::uint8_t>* bytes, const Asked& asked);
  /// After a request: its reply's bytes, or nullptr for its recorded error (errno set).
  const std::vector<std::uint8_t>* reply(const char* kind, const Asked& asked);
  const SessionLogLine* peek() { return lines_.peek(); }

  std::string device_;
  ReplayFeed<SessionLogLine> lines_;
};

}  // namespace station
