// P300 command spellings and strict reply parsers.
#include "drivers/chamber/espec_p300/p300_wire.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>

#include "drivers/ascii/number_field.hpp"

namespace station::drivers::espec_p300 {
namespace {

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  for (;;) {
    const auto i = s.find(sep);
    out.push_back(s.substr(0, i));
    if (i == std::string_view::npos) return out;
    s.remove_prefix(i + 1);
  }
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  return s;
}

std::optional<double> number(std::string_view s) {
  return ascii::number_field(s);
}

std::optional<int> integer(std::string_view s) {
  s = trim(s);
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return v;
}

}  // namespace

std::string temp_setpoint_command(double setpoint_c) {
  return fmt::format("TEMP, S{:.1f}", setpoint_c);
}

std::string addressed(std::string_view command, int address) {
  return address > 0 ? fmt::format("{},{}", address, command) : std::string(command);
}

bool is_error(std::string_view reply, std::string* message) {
  if (reply.substr(0, kErrorPrefix.size()) != kErrorPrefix) return false;
  if (message != nullptr) *message = std::string(reply.substr(kErrorPrefix.size()));
  return true;
}

std::optional<TempReply> parse_temp(std::string_view reply) {
  const auto f = split(reply, ',');
  if (f.size() != 4) return std::nullopt;
  auto pv = number(f[0]), sp = number(f[1]), hi = number(f[2]), lo = number(f[3]);
  if (!pv || !sp || !hi || !lo) return std::nullopt;
  return TempReply{*pv, *sp, *hi, *lo};
}

std::optional<MonReply> parse_mon(std::string_view reply) {
  const auto f = split(reply, ',');
  if (f.size() != 4) return std::nullopt;
  auto t = number(f[0]);
  auto n = integer(f[3]);
  if (!t || !n || *n < 0 || parse_mode(trim(f[2])) == Mode::unknown) return std::nullopt;
  return MonReply{*t, std::string(trim(f[2])), *n};
}

std::optional<std::vector<int>> parse_alarm(std::string_view reply) {
  const auto f = split(reply, ',');
  auto count = integer(f[0]);
  if (!count || *count < 0) return std::nullopt;
  std::vector<int> codes;
  for (std::size_t i = 1; i < f.size(); ++i) {
    auto c = integer(f[i]);
    if (!c) return std::nullopt;
    codes.push_back(*c);
  }
  return codes;
}

std::optional<double> parse_product(std::string_view reply) {
  const auto f = split(reply, ',');
  if (f.size() != 7) return std::nullopt;
  return number(f[1]);
}

Mode parse_mode(std::string_view word) {
  if (word == "OFF") return Mode::off;
  if (word == "STANDBY") return Mode::standby;
  if (word == "CONSTANT") return Mode::constant;
  if (word.substr(0, 3) == "RUN") return Mode::run;
  return Mode::unknown;
}

}  // namespace station::drivers::espec_p300
