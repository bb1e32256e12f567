// A single-axis rate table on an Acutronic ACUTROL3000 (dialect "acutrol3000"), ASCII command
// language over TCP (port 9878) or a serial line (through the MOXA server the maker ships,
// TM-9411), replies framed as configured or recognized at connect, refusals read the ACL way
// (acl_link.hpp). The ACUTROL has no axis-lock register: the station's "lock" is a position-mode
// servo hold, reported locked once the axis is in position. Constructor does no I/O.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "drivers/modbus/readback.hpp"
#include "drivers/turntable/acutrol3000/acl_link.hpp"
#include "drivers/turntable/turntable.hpp"

namespace station::drivers {

class Acutrol3000Table final : public Turntable {
 public:
  /// In position: |angle - demand| below this, deg, and |rate| below kSettledRateDps.
  static constexpr double kInPositionDeg = 0.01, kSettledRateDps = 0.01;

  Acutrol3000Table(std::string name, ascii::LineEndpoint endpoint, double timeout_s,
                   std::unique_ptr<ascii::LineWire> wire = nullptr,
                   acutrol3000::Framing framing = acutrol3000::Framing::automatic);

  Result<void> connect() override;
  Result<TurntableState> read() override;
  /// Closes an open interlock, sets the demand, then the mode; a rate beyond the unit's rate
  /// limit (:Limit:Rate? R,1, read at connect) is ErrorKind::range and nothing is sent. A
  /// latched interlock fault is an error: it needs :Interlock:Reset, an operator's decision. A
  /// command the unit refuses is ErrorKind::exception naming it and the unit's reason.
  Result<void> command(const TurntableCommand& c) override;
  /// :Mode:Off 1, the unit's controlled stop ([ACL] p. 150).
  Result<void> stop() override;
  std::string name() const override { return name_; }
  /// Twice the rate limit the unit reports ([ACL] p. 145, `:Limit:Rate? R,1`, read at connect):
  /// it refuses any demand beyond it, so a measured rate beyond its double is no reading (a servo
  /// overshoots its demand by far less). Unbounded (finite) until the limit is known.
  PlausibleRange rate_range_dps() const override;
  /// *IDN? ([ACL] p. 15), the reply framing in use and the rate limit, for probe.
  Result<std::string> identify() override;

  void set_tap(Tap* tap) { link_.set_tap(tap); }
  void set_clock(const Clock* clock) { link_.set_clock(clock); }
  void set_readback_every(int reads) { readback_.set_every(reads); }

 private:
  Result<double> number(std::string_view query);
  Result<acutrol3000::Interlock> interlock();
  Result<void> read_rate_limit();

  std::string name_;
  acutrol3000::AclLink link_;
  modbus::ReadbackSchedule readback_;
  std::optional<double> rate_limit_dps_;
  std::uint64_t limit_connects_ = 0;  // the connection the limit was read on
  double position_demand_deg_ = 0, rate_demand_dps_ = 0;
};

}  // namespace station::drivers
