// The chamber model served on the ESPEC P300's ASCII dialect, answering as its source says the
// device does (sim_devices/sources/espec_p300_sources.hpp). The ACUTROL3000 table:
// acutrol_face.hpp.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/line_server.hpp"

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
  std::string error_reply(std::string_view request, int code) override;

 private:
  std::string answer(std::string_view command);
  std::string set_temp(std::string_view args);
  std::string alarm_codes() const;

  ChamberSim& chamber_;
  int address_;
};

}  // namespace station::sim
