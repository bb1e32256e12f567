// P300 and ACUTROL3000 command interpreters over the chamber and table models.
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

std::string P300Face::error_reply(std::string_view, int) const {
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
  const double pv = chamber_.air_sensor_failed() ? cfg.broken_sensor_c : chamber_.air_c();
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

// ------------------------------------------------------------------------- ACUTROL3000
namespace {

// A header path like ":dem:pos" matched by unique prefixes against the long forms ([ACL] p. 2).
std::string canonical_path(std::string_view header) {
  static const std::vector<std::string> kWords{"MODE",   "OFF",   "POSITION",  "RATE",
                                               "DEMAND", "READ",  "INTERLOCK", "CLOSE",
                                               "OPEN",   "RESET", "LIMIT",     "IDN"};
  std::string out;
  std::size_t i = 0;
  while (i < header.size()) {
    if (header[i] == ':') {
      ++i;
      continue;
    }
    auto j = header.find(':', i);
    std::string w = upper(header.substr(i, j == std::string_view::npos ? j : j - i));
    i = j == std::string_view::npos ? header.size() : j;
    std::string match;
    for (const auto& k : kWords)
      if (!w.empty() && k.rfind(w, 0) == 0) match = match.empty() ? k : "?";
    out += ":" + (match.empty() || match == "?" ? "?" + w : match);
  }
  return out;
}

}  // namespace

std::string AcutrolFace::error_reply(std::string_view, int) const {
  return "Error: execution error";
}

std::optional<std::string> AcutrolFace::one(const std::string& path, std::string_view args) {
  const bool axis1 = args.substr(0, 1) == "1";
  const auto value = [&]() -> std::optional<double> {
    const auto c = args.find(',');
    return c == std::string_view::npos ? std::nullopt : num(args.substr(c + 1));
  };
  const auto fmt5 = [](double v) { return fmt::format("{:.5f}", v); };
  if (path == ":READ:POSITION?" && axis1) return fmt5(table_.angle_deg());
  if (path == ":READ:RATE?" && axis1) return fmt5(table_.rate_dps());
  if (path == ":MODE?" && axis1) {
    const int m = table_.mode();
    return std::string(m == 1 ? "Position" : m == 2 ? "Rate" : "Off");
  }
  if (path == ":INTERLOCK?" && axis1)
    // A tripped safety interlock (the e-stop chain) or a drive fault shows as a fault.
    return std::string(table_.fault() || table_.interlock_open() ? "Fault"
                       : !interlock_closed_                      ? "Open"
                                                                 : "Close");
  if (path == ":INTERLOCK:CLOSE" && axis1) {
    interlock_closed_ = !table_.fault() && !table_.interlock_open();
    return std::string{};
  }
  if (path == ":INTERLOCK:RESET") return std::string{};  // clears nothing the model latches
  if (path == ":LIMIT:RATE?" && (args == "R,1" || upper(args) == "RATE,1"))
    return fmt5(rate_limit_dps_);
  if (path == ":DEMAND:POSITION?" && axis1) return fmt5(table_.position_demand_deg());
  if (path == ":DEMAND:RATE?" && axis1) return fmt5(table_.rate_demand_dps());
  if (path == ":DEMAND:POSITION" && axis1 && value()) {
    table_.set_position_demand_deg(*value());
    return std::string{};
  }
  if (path == ":DEMAND:RATE" && axis1 && value()) {
    if (std::abs(*value()) > rate_limit_dps_) return std::string("Error: parameter out of range");
    table_.set_rate_demand_dps(*value());
    return std::string{};
  }
  const int mode = path == ":MODE:OFF"        ? 0
                   : path == ":MODE:POSITION" ? 1
                   : path == ":MODE:RATE"     ? 2
                                              : -1;
  if (mode >= 0 && axis1) {
    if (mode == 0) {  // off is always taken: with the interlock open the axis is off already
      (void)table_.set_mode(0);
      return std::string{};
    }
    if (!interlock_closed_) return std::string("Error: interlock open");
    return table_.set_mode(mode) ? std::string{} : std::string("Error: interlock open");
  }
  return std::nullopt;
}

std::optional<std::string> AcutrolFace::handle(std::string_view request) {
  if (!request.empty() && request.back() == '\r') request.remove_suffix(1);
  if (upper(request) == "*IDN?") return "Acutronic,Acutrol3000 SIM,0,sim-1.0";
  std::vector<std::string> replies;
  std::string subsystem;
  bool any_reply = false;
  while (!request.empty()) {
    const auto semi = request.find(';');
    std::string_view part = request.substr(0, semi);
    request = semi == std::string_view::npos ? std::string_view{} : request.substr(semi + 1);
    while (!part.empty() && part.front() == ' ') part.remove_prefix(1);
    const auto sp = part.find(' ');
    std::string header(part.substr(0, sp));
    const std::string_view args = sp == std::string_view::npos ? "" : part.substr(sp + 1);
    // Chained without ':' stays in the previous subsystem ([ACL] p. 3).
    if (!header.empty() && header.front() != ':' && !subsystem.empty())
      header = subsystem + ":" + header;
    std::string path = canonical_path(header);
    const bool query = !header.empty() && header.back() == '?';
    if (query && path.back() != '?') path += "?";
    if (query) {
      auto q = path;
      q.pop_back();
      path = canonical_path(std::string_view(header).substr(0, header.size() - 1)) + "?";
    }
    subsystem = header.substr(0, header.find(':', 1));
    auto r = one(path, args);
    if (!r) return std::string("Error: command not recognized");
    if (!r->empty()) any_reply = true;
    replies.push_back(*r);
  }
  std::string out;
  for (const auto& r : replies)
    if (!r.empty()) out += (out.empty() ? "" : ";") + r;
  (void)any_reply;
  return out;
}

}  // namespace station::sim
