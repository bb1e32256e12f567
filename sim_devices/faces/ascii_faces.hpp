// The chamber and table models served on the ASCII dialects: an ESPEC P300 and an Acutronic
// ACUTROL3000, answering as their sources say the devices do (drivers/chamber/espec_p300/
// p300_wire.hpp, drivers/turntable/acutrol3000/acutrol_wire.hpp and the documents they cite).
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/line_server.hpp"
#include "sim_devices/turntable_sim.hpp"

namespace station::sim {

/// ESPEC P300: TEMP?, TEMP, S.., MON?, MODE?, MODE,.., POWER,ON, ALARM?, TEMP PTC?, ROM?;
/// errors NA:CMD ERR / NA:PARA ERR / NA:DATA OUT OF RANGE; an RS-485 "N," prefix is accepted
/// when it carries this unit's address (another address: no answer).
class P300Face final : public LineDevice {
 public:
  explicit P300Face(ChamberSim& chamber, int address = 1) : chamber_(chamber), address_(address) {}
  std::string request_terminator() const override { return "\r\n"; }
  std::string reply_terminator() const override { return "\r\n"; }
  std::optional<std::string> handle(std::string_view request) override;
  std::string error_reply(std::string_view request, int code) const override;

 private:
  std::string answer(std::string_view command);
  std::string set_temp(std::string_view args);
  std::string alarm_codes() const;

  ChamberSim& chamber_;
  int address_;
};

/// ACUTROL3000 (axis 1): *IDN?, :Mode..., :Demand..., :Read..., :Interlock..., :Limit:Rate,
/// case-insensitive prefixes, ';'-chained commands. Commands without data answer an empty line.
class AcutrolFace final : public LineDevice {
 public:
  explicit AcutrolFace(TurntableSim& table, double rate_limit_dps = 1000.0)
      : table_(table), rate_limit_dps_(rate_limit_dps) {}
  std::string request_terminator() const override { return "\n"; }
  std::string reply_terminator() const override { return "\n"; }
  std::optional<std::string> handle(std::string_view request) override;
  std::string error_reply(std::string_view request, int code) const override;

 private:
  std::optional<std::string> one(const std::string& path, std::string_view args);

  TurntableSim& table_;
  double rate_limit_dps_;
  bool interlock_closed_ = false;
};

}  // namespace station::sim
