// Register-map overrides and the config-spelling parsers.
#include "drivers/modbus/map_overrides.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace station::drivers::modbus {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

[[noreturn]] void bad(std::string_view what, std::string_view value, std::string_view allowed) {
  throw std::invalid_argument("invalid " + std::string(what) + " '" + std::string(value) +
                              "' (expected " + std::string(allowed) + ")");
}

void check_point(const RegisterMap& map, const Point& p) {
  auto where = "register map '" + map.device() + "' point '" + p.name + "': ";
  if (p.scale == 0 || !std::isfinite(p.scale))
    throw std::invalid_argument(where + "scale must be finite and non-zero");
  if (p.unit_id < 0 || p.unit_id > 247)
    throw std::invalid_argument(where + "unit_id " + std::to_string(p.unit_id) + " not in 0..247");
  if (p.one_based && p.address == 0)
    throw std::invalid_argument(where + "address 0 with one-based addressing");
  // A float32 at PDU address 65535 would need register 65536: no Modbus request can read it.
  if (p.pdu_address() + p.word_count() > 65536)
    throw std::invalid_argument(where + "registers past 65535 (the last register is 65535)");
  if (p.access == Access::rw && p.function == FunctionCode::input)
    throw std::invalid_argument(where + "input registers (function 4) cannot be rw");
}

}  // namespace

void apply_overrides(RegisterMap& map, const std::vector<PointOverride>& overrides) {
  for (const auto& o : overrides) {
    Point p = map.at(o.name);  // throws naming the unknown point
    if (o.address) p.address = *o.address;
    if (o.type) p.type = *o.type;
    if (o.scale) p.scale = *o.scale;
    if (o.order) p.order = *o.order;
    if (o.function) p.function = *o.function;
    if (o.unit_id) p.unit_id = *o.unit_id;
    if (o.one_based) p.one_based = *o.one_based;
    if (o.access) p.access = *o.access;
    check_point(map, p);
    map.set(std::move(p));
  }
}

PointType parse_point_type(std::string_view s) {
  auto l = lower(s);
  if (l == "int16") return PointType::int16;
  if (l == "uint16") return PointType::uint16;
  if (l == "float32") return PointType::float32;
  bad("point type", s, "int16, uint16 or float32");
}

WordOrder parse_word_order(std::string_view s) {
  auto l = lower(s);
  if (l == "abcd") return WordOrder::abcd;
  if (l == "cdab") return WordOrder::cdab;
  bad("word order", s, "ABCD or CDAB");
}

WordOrder parse_float_word_order(std::string_view s) {
  if (s == "low_high") return WordOrder::cdab;
  if (s == "high_low") return WordOrder::abcd;
  bad("word order", s, "\"low_high\" (low word first) or \"high_low\"");
}

const char* float_word_order_name(WordOrder order) {
  return order == WordOrder::cdab ? "low_high" : "high_low";
}

int set_float_word_order(RegisterMap& map, WordOrder order) {
  int n = 0;
  for (const auto& [name, point] : map.points()) {
    if (point.type != PointType::float32) continue;
    Point p = point;
    p.order = order;
    map.set(std::move(p));
    ++n;
  }
  return n;
}

FunctionCode parse_function_code(std::string_view s) {
  auto l = lower(s);
  if (l == "3" || l == "holding") return FunctionCode::holding;
  if (l == "4" || l == "input") return FunctionCode::input;
  bad("function code", s, "3/holding or 4/input");
}

Access parse_access(std::string_view s) {
  auto l = lower(s);
  if (l == "ro") return Access::ro;
  if (l == "rw") return Access::rw;
  bad("access", s, "ro or rw");
}

}  // namespace station::drivers::modbus
