// run_fault_command: split a line into words, check them, and call the SimWorld fault setters.
#include "sim_devices/fault_commands.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "sim_devices/sim_world.hpp"

namespace station::sim {
namespace {

struct CommandDoc {
  const char* syntax;
  const char* what;
};

constexpr CommandDoc kCommands[] = {
    {"door open|close", "chamber door switch: GPIO DOOR_SW and the chamber's door alarm bit"},
    {"estop press|release", "e-stop: GPIO ESTOP and the turntable interlock (drive disabled)"},
    {"chamber alarm high-limit on|off", "high-limit trip: alarm bit, chamber output off"},
    {"chamber alarm sensor on|off",
     "air sensor break as the face shows it (generic: alarm bit, air 999.9; F4T: PV NaN)"},
    {"chamber setpoint C", "someone else writes the setpoint (front panel, another master)"},
    {"chamber air C|off",
     "the air reading shows C (a lying sensor or reply; an integer face saturates, -32768 at the "
     "bottom) until off"},
    {"table rate DPS|off", "the rate reading shows DPS (a lying encoder or reply) until off"},
    {"table fault on|off", "turntable drive fault bit (drive disabled)"},
    {"chamber|table stall SECONDS", "no reply to any request for SECONDS (0 ends it)"},
    {"chamber|table exception CODE [N|always]", "exception CODE (1..11) to the next N requests"},
    {"chamber|table refuse SECONDS",
     "every request refused for SECONDS: Modbus exception 6 (busy), an ACUTROL's ACL error "
     "(ILLEGAL CMD in its error queue / header), a P300's NA: line"},
    {"chamber|table drip SECONDS [MS]",
     "every reply in the next SECONDS leaves one byte every MS ms (default 300: a slow proxy), "
     "replies behind it queued in order (0 ends it)"},
    {"chamber|table disconnect [SECONDS]", "close connections, refuse new ones for SECONDS"},
    {"chamber|table clear", "end that device's Modbus faults"},
    {"can drop|duplicate|corrupt N", "the next N counter-board frames on the bus"},
    {"can drop|duplicate|corrupt rate P", "each frame with probability P (0..1) from now on"},
    {"can clear", "end the CAN faults"},
    {"board NODE reset", "board power cycle: counters and board clock restart from 0"},
    {"board NODE silent|answer", "the board stops / resumes answering SYNC"},
    {"gyro NODE temp CHANNEL fail|ok", "temperature channel 0..2 reads the sentinel 0x8000"},
    {"status", "one line: what is injected now"},
    {"clear", "end every fault"},
    {"help", "list the commands"},
};

using Args = std::vector<std::string_view>;

// The drip of issue 34: a proxy forwarding one byte every 0.3 s, under libmodbus's 0.5 s byte
// timeout, so only a deadline for the whole exchange ends it.
constexpr double kDripMs = 300;

Args split(std::string_view line) {
  Args out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    std::size_t j = i;
    while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

[[noreturn]] void usage(std::string_view syntax) {
  throw std::invalid_argument(fmt::format("usage: {}", syntax));
}

double number(std::string_view s, std::string_view what, double lo, double hi) {
  const std::string text(s);
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi)
    throw std::invalid_argument(
        fmt::format("{} '{}' is not a number in [{}, {}]", what, s, lo, hi));
  return v;
}

int integer(std::string_view s, std::string_view what, int lo, int hi) {
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || v < lo || v > hi)
    throw std::invalid_argument(
        fmt::format("{} '{}' is not an integer in {}..{}", what, s, lo, hi));
  return v;
}

// True for `on`, false for `off`; anything else is a usage error.
bool pick(std::string_view s, std::string_view on, std::string_view off, std::string_view syntax) {
  if (s == on) return true;
  if (s != off) usage(syntax);
  return false;
}

std::string modbus_fault(SimServer& server, const Args& a, std::string_view dev) {
  const std::string syntax =
      fmt::format("{} stall|exception|refuse|drip|disconnect|clear ...", dev);
  if (a.size() < 2) usage(syntax);
  if (a[1] == "stall" && a.size() == 3) {
    server.stall_for(number(a[2], "seconds", 0, 1e6));
  } else if (a[1] == "exception" && (a.size() == 3 || a.size() == 4)) {
    const int code = integer(a[2], "exception code", 1, 11);
    const int n = a.size() == 3 ? 1 : a[3] == "always" ? -1 : integer(a[3], "count", 1, 1000000);
    server.inject_exception(code, n);
  } else if (a[1] == "refuse" && a.size() == 3) {
    // Modbus Application Protocol v1.1b3 §7: 06 "Server Device Busy" (a line device refuses
    // in its own words: LineDevice::error_reply).
    server.refuse_for(number(a[2], "seconds", 0, 1e6), 6);
  } else if (a[1] == "drip" && (a.size() == 3 || a.size() == 4)) {
    const double ms = a.size() == 4 ? number(a[3], "milliseconds", 1, 60000) : kDripMs;
    server.drip_for(number(a[2], "seconds", 0, 1e6), ms / 1000.0);
  } else if (a[1] == "disconnect" && a.size() <= 3) {
    server.disconnect_for(a.size() == 3 ? number(a[2], "seconds", 0, 1e6) : 0.0);
  } else if (a[1] == "clear" && a.size() == 2) {
    server.clear_faults();
  } else {
    usage(syntax);
  }
  return "ok";
}

std::string chamber(SimWorld& w, const Args& a) {
  if (a.size() == 4 && a[1] == "alarm") {
    const bool on = pick(a[3], "on", "off", "chamber alarm high-limit|sensor on|off");
    if (a[2] == "high-limit") {
      w.chamber().set_high_limit_trip(on);
    } else if (a[2] == "sensor") {
      w.chamber().set_air_sensor_failed(on);
    } else {
      usage("chamber alarm high-limit|sensor on|off");
    }
    return "ok";
  }
  if (a.size() == 3 && a[1] == "air") {
    // Any finite value, however absurd: the point is a reading no chamber could give.
    w.chamber().set_air_shown_c(a[2] == "off" ? std::nullopt
                                              : std::optional(number(a[2], "air", -1e308, 1e308)));
    return "ok";
  }
  if (a.size() == 3 && a[1] == "setpoint") {
    w.chamber().set_setpoint_c(number(a[2], "setpoint", -1000, 1000));
    return fmt::format("ok setpoint_c={:.1f}", w.chamber().setpoint_c());
  }
  return modbus_fault(w.chamber_server(), a, "chamber");
}

std::string table(SimWorld& w, const Args& a) {
  if (a.size() == 3 && a[1] == "fault") {
    w.turntable().set_fault(pick(a[2], "on", "off", "table fault on|off"));
    return "ok";
  }
  if (a.size() == 3 && a[1] == "rate") {
    w.turntable().set_rate_shown_dps(
        a[2] == "off" ? std::nullopt : std::optional(number(a[2], "rate", -1e308, 1e308)));
    return "ok";
  }
  return modbus_fault(w.turntable_server(), a, "table");
}

CounterBoardBus& bus(SimWorld& w) {
  if (w.bus() == nullptr) throw std::invalid_argument("no station is connected to the CAN bus");
  return *w.bus();
}

std::string can(SimWorld& w, const Args& a) {
  constexpr std::string_view syntax = "can drop|duplicate|corrupt N | ... rate P | can clear";
  if (a.size() == 2 && a[1] == "clear") {
    w.set_can_fault_rates({});
    if (w.bus()) w.bus()->clear_faults();
    return "ok";
  }
  if (a.size() < 3 || (a[1] != "drop" && a[1] != "duplicate" && a[1] != "corrupt")) usage(syntax);
  if (a[2] == "rate" && a.size() == 4) {
    BusFaultRates r = w.can_fault_rates();
    const double p = number(a[3], "probability", 0, 1);
    (a[1] == "drop" ? r.drop : a[1] == "duplicate" ? r.duplicate : r.corrupt) = p;
    w.set_can_fault_rates(r);
    return "ok";
  }
  if (a.size() != 3) usage(syntax);
  const int n = integer(a[2], "count", 0, 1000000);
  if (a[1] == "drop") bus(w).drop_frames(n);
  if (a[1] == "duplicate") bus(w).duplicate_frames(n);
  if (a[1] == "corrupt") bus(w).corrupt_frames(n, CorruptKind::bad_dlc);
  return "ok";
}

std::string board(SimWorld& w, const Args& a) {
  if (a.size() != 3) usage("board NODE reset|silent|answer");
  const auto node = static_cast<std::uint8_t>(integer(a[1], "node", 1, 16));
  if (a[2] == "reset") {
    bus(w).reset_board(node);
  } else {
    w.set_board_answering(node, !pick(a[2], "silent", "answer", "board NODE reset|silent|answer"));
  }
  return "ok";
}

std::string gyro(SimWorld& w, const Args& a) {
  constexpr std::string_view syntax = "gyro NODE temp CHANNEL fail|ok";
  if (a.size() != 5 || a[2] != "temp") usage(syntax);
  const auto node = static_cast<std::uint8_t>(integer(a[1], "node", 1, 16));
  w.set_gyro_temp_failed(node, integer(a[3], "channel", 0, 2), pick(a[4], "fail", "ok", syntax));
  return "ok";
}

std::string status(SimWorld& w) {
  const BusFaultRates& r = w.can_fault_rates();
  return fmt::format(
      "ok t_s={:.1f} door={} estop={} chamber_alarms=0x{:x} chamber_setpoint_c={:.1f} "
      "can_rates=drop:{},duplicate:{},corrupt:{} station_on_can={}",
      w.now_s(), w.door_open() ? "open" : "closed", w.estop_pressed() ? "pressed" : "released",
      w.chamber().alarms(), w.chamber().setpoint_c(), r.drop, r.duplicate, r.corrupt,
      w.bus() != nullptr ? "yes" : "no");
}

std::string dispatch(SimWorld& w, const Args& a) {
  if (a.empty()) throw std::invalid_argument("empty command (try: help)");
  const std::string_view verb = a[0];
  if (verb == "door" && a.size() == 2) {
    w.set_door_open(pick(a[1], "open", "close", "door open|close"));
  } else if (verb == "estop" && a.size() == 2) {
    w.set_estop(pick(a[1], "press", "release", "estop press|release"));
  } else if (verb == "chamber") {
    return chamber(w, a);
  } else if (verb == "table") {
    return table(w, a);
  } else if (verb == "can") {
    return can(w, a);
  } else if (verb == "board") {
    return board(w, a);
  } else if (verb == "gyro") {
    return gyro(w, a);
  } else if (verb == "status" && a.size() == 1) {
    return status(w);
  } else if (verb == "clear" && a.size() == 1) {
    w.clear_faults();
  } else if (verb == "help" && a.size() == 1) {
    std::string out = "ok";
    for (const auto& c : kCommands) out += fmt::format("{} {}", out == "ok" ? "" : ";", c.syntax);
    return out;
  } else {
    throw std::invalid_argument(fmt::format("unknown command '{}' (try: help)", verb));
  }
  return "ok";
}

}  // namespace

std::string fault_command_help() {
  std::string out;
  for (const auto& c : kCommands) out += fmt::format("  {:<42} {}\n", c.syntax, c.what);
  return out;
}

std::string run_fault_command(SimWorld& world, std::string_view line) {
  try {
    return dispatch(world, split(line));
  } catch (const std::exception& e) {
    return fmt::format("error: {}", e.what());
  }
}

}  // namespace station::sim
