// ACUTROL3000 command spellings, framing names and strict reply parsers.
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

std::optional<Framing> framing_from_name(std::string_view name) {
  if (name == "auto") return Framing::automatic;
  if (name == "bare") return Framing::bare;
  if (name == "header") return Framing::header;
  return std::nullopt;
}

const char* to_string(Framing f) {
  switch (f) {
    case Framing::automatic:
      return "auto";
    case Framing::bare:
      return "bare";
    case Framing::header:
      return "header";
  }
  return "?";
}

std::uint32_t frame_error_code(std::string_view header) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(header.at(i));
  return v;
}

std::string error_text_query(std::uint32_t code) {
  return fmt::format(":Query:Error? {}", code);
}

std::optional<unsigned> parse_status_byte(std::string_view reply) {
  const auto v = parse_number(reply);
  if (!v || *v < 0 || *v > 255 || *v != std::floor(*v)) return std::nullopt;
  return static_cast<unsigned>(*v);
}

double wrap_deg(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w < 0) w += 360.0;
  return w >= 360.0 ? 0.0 : w;
}

}  // namespace station::drivers::acutrol3000
