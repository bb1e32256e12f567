// Acutrol3000Table: the ACUTROL3000 command language behind the Turntable interface.
#include "drivers/turntable/acutrol3000/acutrol3000_table.hpp"

#include <fmt/format.h>

#include <cmath>

#include "drivers/turntable/acutrol3000/acutrol_wire.hpp"

namespace station::drivers {
namespace ac = acutrol3000;

Acutrol3000Table::Acutrol3000Table(std::string name, ascii::LineEndpoint endpoint, double timeout_s,
                                   std::unique_ptr<ascii::LineWire> wire)
    : name_(std::move(name)),
      client_(name_, std::move(endpoint),
              ascii::LineFraming{std::string(ac::kCommandTerminator),
                                 std::string(ac::kReplyTerminator), 256},
              std::move(wire), timeout_s) {}

Result<std::string> Acutrol3000Table::ask(std::string_view command) {
  auto reply = client_.query(command);
  if (!reply) return reply;
  if (ac::is_error(reply.value()))
    return make_error(ErrorKind::exception,
                      fmt::format("{}: '{}' refused: {}", name_, command, reply.value()));
  return reply;
}

// A command without data: the unit answers an empty line ([RN] p. 5).
Result<void> Acutrol3000Table::set(std::string_view command) {
  auto reply = ask(command);
  if (!reply) return reply.error();
  return {};
}

Result<double> Acutrol3000Table::number(std::string_view query) {
  auto reply = ask(query);
  if (!reply) return reply.error();
  auto v = ac::parse_number(reply.value());
  if (!v)
    return make_error(ErrorKind::protocol, fmt::format("{}: reply '{}' to '{}' is not a number",
                                                       name_, reply.value(), query));
  return *v;
}

Result<void> Acutrol3000Table::connect() {
  if (auto c = client_.connect(); !c) return c;
  return read_rate_limit();
}

// The unit's rate limit, read on every new connection (the unit may have been reconfigured or
// restarted); until it is known no rate demand is sent.
Result<void> Acutrol3000Table::read_rate_limit() {
  limit_connects_ = client_.connects();
  auto limit = number(ac::kRateLimitQuery);
  if (!limit) {
    rate_limit_dps_.reset();
    return limit.error();
  }
  rate_limit_dps_ = std::abs(limit.value());
  return {};
}

Result<TurntableState> Acutrol3000Table::read() {
  const bool full = readback_.due(client_.connects());
  auto pr = ask(ac::kReadPositionRate);
  auto mode = pr ? ask(ac::kModeQuery) : pr;
  auto il = mode ? ask(ac::kInterlockQuery) : mode;
  Result<double> pd = il ? (full ? number(ac::kPositionDemandQuery) : Result<double>(0.0))
                         : Result<double>(il.error());
  Result<double> rd = pd ? (full ? number(ac::kRateDemandQuery) : Result<double>(0.0)) : pd;
  if (!rd) {
    readback_.read_done(false, full, client_.connects());
    return rd.error();
  }
  const auto p = ac::parse_position_rate(pr.value());
  const auto m = ac::parse_mode(mode.value());
  const auto i = ac::parse_interlock(il.value());
  const bool parsed = p && m != ac::Mode::unknown && i != ac::Interlock::unknown;
  readback_.read_done(parsed, full, client_.connects());
  if (!parsed)
    return make_error(ErrorKind::protocol,
                      fmt::format("{}: replies '{}' / '{}' / '{}' do not parse", name_, pr.value(),
                                  mode.value(), il.value()));
  if (full) position_demand_deg_ = pd.value(), rate_demand_dps_ = rd.value();
  TurntableState s;
  s.angle_deg = ac::wrap_deg(p->first);
  s.rate_dps = p->second;
  s.mode = m == ac::Mode::position ? TurntableMode::position
           : m == ac::Mode::rate   ? TurntableMode::rate
                                   : TurntableMode::off;
  const double err = std::abs(std::remainder(p->first - position_demand_deg_, 360.0));
  s.in_position = s.mode == TurntableMode::position && err < kInPositionDeg &&
                  std::abs(s.rate_dps) < kSettledRateDps;
  s.at_rate = s.mode == TurntableMode::rate &&
              std::abs(s.rate_dps - rate_demand_dps_) <=
                  std::max(kSettledRateDps, 1e-4 * std::abs(rate_demand_dps_));
  // "Open" is the servo not yet enabled (the unit starts so; command() closes it); a safety
  // interlock that tripped (e-stop chain, limit) opens the servo AND latches "Fault" (SI p. 10).
  s.fault = i == ac::Interlock::fault;
  s.interlock_open = i == ac::Interlock::fault;
  s.locked = s.in_position;  // position servo hold: the ACUTROL has no lock register
  return s;
}

Result<void> Acutrol3000Table::command(const TurntableCommand& c) {
  readback_.invalidate();
  if (c.rate_dps && (!rate_limit_dps_ || limit_connects_ != client_.connects())) {
    if (auto ok = read_rate_limit(); !ok) return ok;
  }
  if (c.rate_dps && (!std::isfinite(*c.rate_dps) || std::abs(*c.rate_dps) > *rate_limit_dps_))
    return make_error(ErrorKind::range,
                      fmt::format("{}: rate {} deg/s beyond the unit's rate limit {} deg/s", name_,
                                  *c.rate_dps, rate_limit_dps_.value_or(0)));
  if (c.position_deg && !std::isfinite(*c.position_deg))
    return make_error(ErrorKind::range, fmt::format("{}: position demand not finite", name_));
  if (c.mode == TurntableMode::off) return set(ac::kModeOff);
  auto il = ask(ac::kInterlockQuery);
  if (!il) return il.error();
  const auto state = ac::parse_interlock(il.value());
  if (state == ac::Interlock::fault)
    return make_error(ErrorKind::exception,
                      fmt::format("{}: interlock fault latched: clear the cause, then "
                                  ":Interlock:Reset at the table",
                                  name_));
  if (state != ac::Interlock::closed) {
    if (auto ok = set(ac::kInterlockClose); !ok) return ok;
  }
  if (c.mode == TurntableMode::position) {
    if (c.position_deg) {
      if (auto ok = set(ac::position_demand(ac::wrap_deg(*c.position_deg))); !ok) return ok;
    }
    return set(ac::kModePosition);
  }
  if (c.rate_dps) {
    if (auto ok = set(ac::rate_demand(*c.rate_dps)); !ok) return ok;
  }
  return set(ac::kModeRate);
}

Result<void> Acutrol3000Table::stop() {
  readback_.invalidate();
  return set(ac::kModeOff);
}

Result<std::string> Acutrol3000Table::identify() {
  auto idn = ask(ac::kIdentify);
  if (!idn) return idn;
  auto limit = number(ac::kRateLimitQuery);
  if (!limit) return limit.error();
  return fmt::format("{} (rate limit {} deg/s)", idn.value(), limit.value());
}

}  // namespace station::drivers
