// When a driver reads back its command registers (a chamber's setpoint, ramp and run; a
// turntable's lock): they change only when written — by the station, whose next read then
// confirms the write, or by an operator at the controller's panel, which the periodic read-back
// catches within `every` reads. Live values (temperatures, status, alarms, angle, rate) are read
// on every read regardless. No I/O.
#pragma once

#include <algorithm>
#include <cstdint>

namespace station::drivers::modbus {

class ReadbackSchedule {
 public:
  /// Most reads between two read-backs, >= 1 (1: every read).
  static constexpr int kDefaultEvery = 10;

  void set_every(int reads) { every_ = std::max(1, reads); }
  int every() const { return every_; }
  /// Whether this read must include the command registers. `connects`: the client's count of
  /// successful connects (ModbusClient::connects) — a new connection since the last read-back
  /// may be a restarted device holding anything.
  bool due(std::uint64_t connects) const {
    return stale_ || connects != connects_ || since_ + 1 >= every_;
  }
  /// After a read: `with_commands` whether it read them, `connects` the client's count after
  /// it; a failed read makes the next one full.
  void read_done(bool ok, bool with_commands, std::uint64_t connects) {
    if (!ok) {
      stale_ = true;
    } else if (with_commands) {
      stale_ = false;
      since_ = 0;
      connects_ = connects;
    } else {
      ++since_;
    }
  }
  /// After a write: the next read confirms what the device now holds.
  void invalidate() { stale_ = true; }

 private:
  int every_ = kDefaultEvery;
  int since_ = 0;
  std::uint64_t connects_ = 0;  // the client's connect count at the last read-back
  bool stale_ = true;           // nothing read back yet
};

}  // namespace station::drivers::modbus
