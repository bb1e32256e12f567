// Acutrol3000Table: the ACUTROL3000 command language behind the Turntable interface.
#include "drivers/turntable/acutrol3000/acutrol3000_table.hpp"

#include <fmt/format.h>

#include <cmath>

#include "drivers/turntable/acutrol3000/acutrol_wire.hpp"

namespace station::drivers {
namespace ac = acutrol3000;
namespace {

// The largest position the unit's reply may carry and still be an angle, degrees: far more turns
// than a table makes in a run (a week at its top rate); beyond it the wrap would invent an angle.
constexpr double kMaxPositionDeg = 1e9;

// What each query's reply must be (acutrol_wire.hpp); anything else is no reading.
bool is_number(std::string_view s) {
  return ac::parse_number(s).has_value();
}
bool is_position_rate(std::string_view s) {
  return ac::parse_position_rate(s).has_value();
}
bool is_mode(std::string_view s) {
  return ac::parse_mode(s) != ac::Mode::unknown;
}
bool is_interlock(std::string_view s) {
  return ac::parse_interlock(s) != ac::Interlock::unknown;
}
bool is_text(std::string_view s) {
  return !s.empty();
}

}  // namespace

Acutrol3000Table::Acutrol3000Table(std::string name, ascii::LineEndpoint endpoint, double timeout_s,
                                   std::unique_ptr<ascii::LineWire> wire, ac::Framing framing)
    : name_(name),
      link_(std::move(name), std::move(endpoint), timeout_s, framing, std::move(wire)) {}

Result<double> Acutrol3000Table::number(std::string_view query) {
  auto reply = link_.query(query, is_number);
  if (!reply) return reply.error();
  return *ac::parse_number(reply.value());
}

Result<ac::Interlock> Acutrol3000Table::interlock() {
  auto reply = link_.query(ac::kInterlockQuery, is_interlock);
  if (!reply) return reply.error();
  return ac::parse_interlock(reply.value());
}

Result<void> Acutrol3000Table::connect() {
  if (auto c = link_.connect(); !c) return c;
  return read_rate_limit();
}

// The unit's rate limit, read on every new connection (the unit may have been reconfigured or
// restarted); until it is known no rate demand is sent.
Result<void> Acutrol3000Table::read_rate_limit() {
  limit_connects_ = link_.connects();
  auto limit = number(ac::kRateLimitQuery);
  if (!limit) {
    rate_limit_dps_.reset();
    return limit.error();
  }
  rate_limit_dps_ = std::abs(limit.value());
  return {};
}

PlausibleRange Acutrol3000Table::rate_range_dps() const {
  if (!rate_limit_dps_) return {};
  return {-2.0 * *rate_limit_dps_, 2.0 * *rate_limit_dps_};
}

Result<TurntableState> Acutrol3000Table::read() {
  const bool full = readback_.due(link_.connects());
  auto pr = link_.query(ac::kReadPositionRate, is_position_rate);
  auto mode = pr ? link_.query(ac::kModeQuery, is_mode) : pr;
  auto il = mode ? interlock() : Result<ac::Interlock>(mode.error());
  Result<double> pd = il ? (full ? number(ac::kPositionDemandQuery) : Result<double>(0.0))
                         : Result<double>(il.error());
  Result<double> rd = pd ? (full ? number(ac::kRateDemandQuery) : Result<double>(0.0)) : pd;
  readback_.read_done(rd.ok(), full, link_.connects());
  if (!rd) return rd.error();
  const auto p = ac::parse_position_rate(pr.value());
  const auto m = ac::parse_mode(mode.value());
  const auto i = il.value();
  if (full) position_demand_deg_ = pd.value(), rate_demand_dps_ = rd.value();
  TurntableState s;
  // A position no unit reports (1e308) is no angle: left NaN for the station's screen, never
  // wrapped into [0, 360) as if it were one.
  const bool angle_read = std::isfinite(p->first) && std::fabs(p->first) <= kMaxPositionDeg;
  s.angle_deg = angle_read ? ac::wrap_deg(p->first) : std::nan("");
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
  if (c.rate_dps && (!rate_limit_dps_ || limit_connects_ != link_.connects())) {
    if (auto ok = read_rate_limit(); !ok) return ok;
  }
  if (c.rate_dps && (!std::isfinite(*c.rate_dps) || std::abs(*c.rate_dps) > *rate_limit_dps_))
    return make_error(ErrorKind::range,
                      fmt::format("{}: rate {} deg/s beyond the unit's rate limit {} deg/s", name_,
                                  *c.rate_dps, rate_limit_dps_.value_or(0)));
  if (c.position_deg && !std::isfinite(*c.position_deg))
    return make_error(ErrorKind::range, fmt::format("{}: position demand not finite", name_));
  if (c.mode == TurntableMode::off) return link_.command(ac::kModeOff);
  auto state = interlock();
  if (!state) return state.error();
  if (state.value() == ac::Interlock::fault)
    return make_error(ErrorKind::exception,
                      fmt::format("{}: interlock fault latched: clear the cause, then "
                                  ":Interlock:Reset at the table",
                                  name_));
  if (state.value() != ac::Interlock::closed) {
    if (auto ok = link_.command(ac::kInterlockClose); !ok) return ok;
  }
  if (c.mode == TurntableMode::position) {
    if (c.position_deg) {
      if (auto ok = link_.command(ac::position_demand(ac::wrap_deg(*c.position_deg))); !ok)
        return ok;
    }
    return link_.command(ac::kModePosition);
  }
  if (c.rate_dps) {
    if (auto ok = link_.command(ac::rate_demand(*c.rate_dps)); !ok) return ok;
  }
  return link_.command(ac::kModeRate);
}

Result<void> Acutrol3000Table::stop() {
  readback_.invalidate();
  return link_.command(ac::kModeOff);
}

Result<std::string> Acutrol3000Table::identify() {
  auto idn = link_.query(ac::kIdentify, is_text);
  if (!idn) return idn;
  auto limit = number(ac::kRateLimitQuery);
  if (!limit) return limit.error();
  const ac::Framing used = link_.framing_in_use().value_or(link_.framing());
  return fmt::format(
      "{} (framing {}, {}; rate limit {} deg/s)", idn.value(), ac::to_string(used),
      link_.framing() == ac::Framing::automatic ? "recognized at connect" : "as configured",
      limit.value());
}

}  // namespace station::drivers
