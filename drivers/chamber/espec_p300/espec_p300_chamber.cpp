// EspecP300Chamber: MON?/TEMP? every read, product and alarm codes with the command read-back.
#include "drivers/chamber/espec_p300/espec_p300_chamber.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <variant>

#include "drivers/chamber/espec_p300/p300_wire.hpp"

namespace station::drivers {
namespace p3 = espec_p300;

namespace {

ascii::LineFraming p300_framing() {
  return ascii::LineFraming{std::string(p3::kTerminator), std::string(p3::kTerminator), 256};
}

}  // namespace

EspecP300Chamber::EspecP300Chamber(std::string name, ascii::LineEndpoint endpoint, int address,
                                   double timeout_s, std::unique_ptr<ascii::LineWire> wire)
    : name_(std::move(name)),
      client_(name_, endpoint, p300_framing(), std::move(wire), timeout_s),
      address_(std::holds_alternative<ascii::LineSerial>(endpoint) ? address : 0) {}

// One exchange; an "NA:" reply is the controller refusing the command.
Result<std::string> EspecP300Chamber::ask(std::string_view command) {
  auto reply = client_.query(p3::addressed(command, address_));
  if (!reply) return reply;
  std::string message;
  if (p3::is_error(reply.value(), &message))
    return make_error(ErrorKind::exception,
                      fmt::format("{}: '{}' refused: NA:{}", name_, command, message));
  return reply;
}

Result<void> EspecP300Chamber::read_slow(ChamberState& s, int alarm_count) {
  if (has_product_) {
    auto r = ask(p3::kProductQuery);
    if (!r && r.error().kind == ErrorKind::exception) {
      has_product_ = false;  // no PTCON: the library's feature test (CCL espec.py :666-681)
    } else if (!r) {
      return r.error();
    } else {
      // A non-numeric product field (CCL read_temp_ptc parses with tryfloat) is no reading:
      // the informational product temperature is NaN, the chamber's read goes on.
      product_c_ = p3::parse_product(r.value()).value_or(std::numeric_limits<double>::quiet_NaN());
    }
  }
  other_alarm_ = false;
  if (alarm_count > 0) {
    auto r = ask(p3::kAlarmQuery);
    if (!r) return r.error();
    auto codes = p3::parse_alarm(r.value());
    if (!codes)
      return make_error(
          ErrorKind::protocol,
          fmt::format("{}: ALARM? reply '{}' is not a list of codes", name_, r.value()));
    other_alarm_ = !codes->empty();
  }
  s.product_c = has_product_ ? product_c_ : std::numeric_limits<double>::quiet_NaN();
  return {};
}

Result<ChamberState> EspecP300Chamber::read() {
  const bool full = readback_.due(client_.connects());
  auto mon = ask(p3::kMonitorQuery);
  auto temp = mon ? ask(p3::kTempQuery) : mon;
  if (!temp) {
    readback_.read_done(false, full, client_.connects());
    return temp.error();
  }
  auto m = p3::parse_mon(mon.value());
  auto t = p3::parse_temp(temp.value());
  if (!m || !t) {
    readback_.read_done(false, full, client_.connects());
    return make_error(ErrorKind::protocol,
                      fmt::format("{}: reply '{}' to {} does not parse", name_,
                                  m ? temp.value() : mon.value(), m ? "TEMP?" : "MON?"));
  }
  ChamberState s;
  s.product_c = has_product_ ? product_c_ : std::numeric_limits<double>::quiet_NaN();
  if (full) {
    auto ok = read_slow(s, m->alarms);
    readback_.read_done(ok.ok(), full, client_.connects());
    if (!ok) return ok.error();
  } else {
    readback_.read_done(true, full, client_.connects());
  }
  s.air_c = t->pv_c;
  s.setpoint_c = t->sp_c;
  s.ramp_c_per_min = 0;  // no constant-mode ramp on a P300
  // MON?'s count is fresh every read; the codes (ALARM?) only on the read that asked for them.
  s.alarms.other = m->alarms > 0 || (full && other_alarm_);
  switch (p3::parse_mode(m->mode)) {
    case p3::Mode::constant:
      s.mode = ChamberMode::constant;
      break;
    case p3::Mode::run:
      s.mode = ChamberMode::profile;
      break;
    default:
      s.mode = ChamberMode::off;
  }
  s.run_enabled = s.mode != ChamberMode::off;
  return s;
}

Result<p3::TempReply> EspecP300Chamber::read_temp() {
  auto temp = ask(p3::kTempQuery);
  if (!temp) return temp.error();
  auto t = p3::parse_temp(temp.value());
  if (!t)
    return make_error(ErrorKind::protocol,
                      fmt::format("{}: TEMP? reply '{}' does not parse", name_, temp.value()));
  return *t;
}

Result<void> EspecP300Chamber::command(const ChamberCommand& c) {
  readback_.invalidate();
  if (c.setpoint_c) {
    const auto limits = read_temp();
    if (!limits) return limits.error();
    const p3::TempReply& t = limits.value();
    if (!std::isfinite(*c.setpoint_c) || *c.setpoint_c < t.low_c || *c.setpoint_c > t.high_c)
      return make_error(ErrorKind::range,
                        fmt::format("{}: setpoint {} C outside the chamber limits [{}, {}] C",
                                    name_, *c.setpoint_c, t.low_c, t.high_c));
    if (auto r = ask(p3::temp_setpoint_command(*c.setpoint_c)); !r) return r.error();
  }
  if (c.run) {
    if (auto r = ask(*c.run ? p3::kModeConstant : p3::kModeStandby); !r) return r.error();
  }
  return {};
}

Result<ChamberIdentity> EspecP300Chamber::identify() {
  auto rom = ask(p3::kRomQuery);
  if (!rom) return rom.error();
  const auto temp = read_temp();
  if (!temp) return temp.error();
  const p3::TempReply& t = temp.value();
  ChamberIdentity id;
  id.model = "espec_p300";
  // CCL espec.py process_controller:666: a ROM starting "P3" is a P300, else an SCP-220.
  id.identity =
      fmt::format("ROM {} ({})", rom.value(), rom.value().rfind("P3", 0) == 0 ? "P300" : "SCP-220");
  id.units = "C";  // the P300 protocol is in deg C (CCL espec.py get_loop_units:299-305)
  id.setpoint_low_c = t.low_c;
  id.setpoint_high_c = t.high_c;
  id.notes = "no constant-mode ramp: the station ramps the setpoint; run = MODE,CONSTANT";
  return id;
}

}  // namespace station::drivers
