// An ESPEC P300 (or SCP-220) chamber on its ASCII protocol over TCP (port 10001) or a serial
// line (dialect "espec_p300"). The P300 has no constant-mode ramp (controller_ramp() false: the
// station ramps the setpoint). Run = MODE,CONSTANT; stop = MODE,STANDBY. Constructor does no I/O.
#pragma once

#include <memory>
#include <string>

#include "drivers/ascii/line_client.hpp"
#include "drivers/chamber/chamber.hpp"
#include "drivers/chamber/espec_p300/p300_wire.hpp"
#include "drivers/modbus/readback.hpp"

namespace station::drivers {

class EspecP300Chamber final : public Chamber {
 public:
  /// `address`: the unit's RS-485 address, sent as "N," on a serial line (0: none).
  EspecP300Chamber(std::string name, ascii::LineEndpoint endpoint, int address, double timeout_s,
                   std::unique_ptr<ascii::LineWire> wire = nullptr);

  Result<void> connect() override { return client_.connect(); }
  Result<ChamberState> read() override;
  Result<void> command(const ChamberCommand& c) override;
  std::string name() const override { return name_; }
  Result<ChamberIdentity> identify() override;
  bool controller_ramp() const override { return false; }

  void set_tap(Tap* tap) { client_.set_tap(tap); }
  void set_clock(const Clock* clock) { client_.set_clock(clock); }
  void set_readback_every(int reads) { readback_.set_every(reads); }

 private:
  Result<std::string> ask(std::string_view command);
  /// TEMP? parsed (pv, setpoint, high and low limit); a reply that does not parse is a
  /// protocol error.
  Result<espec_p300::TempReply> read_temp();
  Result<void> read_slow(ChamberState& s, int alarm_count);

  std::string name_;
  ascii::LineClient client_;
  int address_;  // 0 on TCP
  modbus::ReadbackSchedule readback_;
  double product_c_ = 0;
  bool has_product_ = true, other_alarm_ = false;
};

}  // namespace station::drivers
