// The P300 command interpreter over the chamber model.
#include "sim_devices/faces/ascii_faces.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <vector>

#include "drivers/ascii/number_field.hpp"
#include "sim_devices/sources/espec_p300_sources.hpp"

namespace station::sim {
namespace {

std::optional<double> num(std::string_view s) {
  return drivers::ascii::number_field(s);
}

std::string upper(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return out;
}

}  // namespace

// ------------------------------------------------------------------------------- P300
std::optional<std::string> P300Face::handle(std::string_view request) {
  // "N,CMD" on a serial bus: answer only our address (another unit's request is not ours).
  const auto comma = request.find(',');
  if (comma != std::string_view::npos && comma > 0 &&
      std::all_of(request.begin(), request.begin() + static_cast<long>(comma),
                  [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; })) {
    int addr = 0;
    std::from_chars(request.data(), request.data() + comma, addr);
    if (addr != address_) return std::nullopt;
    request.remove_prefix(comma + 1);
  }
  return answer(request);
}

std::string P300Face::error_reply(std::string_view, int) {
  return "NA:CHB NOT READY";
}

std::string P300Face::alarm_codes() const {
  // Simulator's codes (the P300 manual's list is not among the sources): 1 high-limit trip,
  // 2 sensor break, 3 door.
  std::vector<int> codes;
  const unsigned a = chamber_.alarms();
  if ((a & 8u) != 0) codes.push_back(1);
  if ((a & 2u) != 0) codes.push_back(2);
  if ((a & 4u) != 0) codes.push_back(3);
  std::string out = std::to_string(codes.size());
  for (int c : codes) out += "," + std::to_string(c);
  return out;
}

std::string P300Face::set_temp(std::string_view args) {
  // "TEMP, S<sp>" (CCL write_temp:1037): comma, space, S, value.
  if (args.substr(0, 2) != sources::p300::kTempSetPrefix.substr(5)) return "NA:PARA ERR";
  auto v = num(args.substr(2));
  if (!v) return "NA:PARA ERR";
  const auto& cfg = chamber_.config();
  if (*v < cfg.setpoint_low_c || *v > cfg.setpoint_high_c) return "NA:DATA OUT OF RANGE";
  chamber_.set_setpoint_c(*v);
  return fmt::format("{}{}{:.1f}", sources::p300::kOk, sources::p300::kTempSetPrefix, *v);
}

std::string P300Face::answer(std::string_view c) {
  namespace p3 = sources::p300;
  const auto& cfg = chamber_.config();
  const auto mode = [&] { return chamber_.run() ? "CONSTANT" : "STANDBY"; };
  const double pv = chamber_.air_sensor_failed() ? cfg.broken_sensor_c : chamber_.shown_air_c();
  if (c == p3::kTempQuery)
    return fmt::format("{:.1f},{:.1f},{:.1f},{:.1f}", pv, chamber_.setpoint_c(),
                       cfg.setpoint_high_c, cfg.setpoint_low_c);
  if (c == p3::kMonitorQuery) {
    const std::string codes = alarm_codes();
    return fmt::format("{:.1f},,{},{}", pv, mode(), std::count(codes.begin(), codes.end(), ','));
  }
  if (c == p3::kModeQuery) return mode();
  if (c == p3::kAlarmQuery) return alarm_codes();
  if (c == p3::kProductQuery)
    return fmt::format("ON,{:.1f},{:.1f},{:.1f},{:.1f},10.0,10.0", chamber_.product_c(), pv,
                       chamber_.setpoint_c(), chamber_.setpoint_c());
  if (c == p3::kRomQuery) return "P300 SIM 1.00";
  if (c == p3::kModeConstant || c == p3::kPowerOn) {
    chamber_.set_run(true);
    return std::string(p3::kOk) + std::string(c);
  }
  if (c == p3::kModeStandby || c == p3::kModeOff || upper(c) == p3::kPowerOff) {
    chamber_.set_run(false);
    return std::string(p3::kOk) + std::string(c);
  }
  if (c.substr(0, 5) == p3::kTempSetPrefix.substr(0, 5)) return set_temp(c.substr(5));
  return "NA:CMD ERR";
}

}  // namespace station::sim
