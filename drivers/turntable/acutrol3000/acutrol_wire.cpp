// ACUTROL3000 command spellings and strict reply parsers.
#include "drivers/turntable/acutrol3000/acutrol_wire.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "drivers/ascii/number_field.hpp"

namespace station::drivers::acutrol3000 {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  while (!out.empty() && (out.back() == '\r' || out.back() == ' ')) out.pop_back();
  while (!out.empty() && out.front() == ' ') out.erase(out.begin());
  return out;
}

}  // namespace

std::string position_demand(double deg) {
  return fmt::format(":Demand:Position 1,{:.5f}", deg);
}
std::string rate_demand(double dps) {
  return fmt::format(":Demand:Rate 1,{:.5f}", dps);
}

Mode parse_mode(std::string_view reply) {
  const auto w = lower(reply);
  if (w == "o" || w == "off") return Mode::off;
  if (w == "p" || w == "position") return Mode::position;
  if (w == "r" || w == "rate") return Mode::rate;
  for (const char* m : {"arate", "synthesis", "track", "abort", "a", "s", "t"})
    if (w == m) return Mode::other;
  return Mode::unknown;
}

Interlock parse_interlock(std::string_view reply) {
  const auto w = lower(reply);
  if (w == "close" || w == "closed") return Interlock::closed;
  if (w == "open") return Interlock::open;
  if (w == "fault") return Interlock::fault;
  return Interlock::unknown;
}

std::optional<double> parse_number(std::string_view s) {
  return ascii::number_field(s);
}

std::optional<std::pair<double, double>> parse_position_rate(std::string_view reply) {
  const auto i = reply.find(';');
  if (i == std::string_view::npos) return std::nullopt;
  auto p = parse_number(reply.substr(0, i));
  auto r = parse_number(reply.substr(i + 1));
  if (!p || !r) return std::nullopt;
  return std::pair{*p, *r};
}

bool is_error(std::string_view reply) {
  return lower(reply).rfind("error", 0) == 0;
}

double wrap_deg(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w < 0) w += 360.0;
  return w >= 360.0 ? 0.0 : w;
}

}  // namespace station::drivers::acutrol3000
