// GPIO line configuration: role map and line-spec parsing, role lookup, tap records.
#include "drivers/gpio/gpio_bank.hpp"

#include <fmt/format.h>

#include <charconv>
#include <stdexcept>

namespace station::drivers::gpio {

namespace roles {
std::string relay(int slot) {
  return fmt::format("relay.{}", slot);
}
}  // namespace roles

namespace {

constexpr int kMaxRelaySlot = 99;

// Role -> direction and safe level; false if the role is not one the station knows.
bool classify_role(std::string_view role, GpioLineConfig& line) {
  if (role == roles::interlock || role == roles::estop) {
    line.direction = GpioDirection::input;
    return true;
  }
  line.direction = GpioDirection::output;
  if (role == roles::tower_green || role == roles::tower_amber) {
    line.safe_level = false;
    return true;
  }
  if (role == roles::tower_red) {
    line.safe_level = true;
    return true;
  }
  constexpr std::string_view relay_prefix = "relay.";
  if (role.starts_with(relay_prefix)) {
    const std::string_view num = role.substr(relay_prefix.size());
    int slot = 0;
    const auto [end, ec] = std::from_chars(num.data(), num.data() + num.size(), slot);
    if (ec != std::errc{} || end != num.data() + num.size() || slot < 1 || slot > kMaxRelaySlot)
      return false;
    line.safe_level = false;
    return true;
  }
  return false;
}

}  // namespace

std::string GpioLineConfig::where() const {
  if (!line_name.empty()) return line_name;
  return fmt::format("{}:{}", chip, offset);
}

void parse_line_spec(std::string_view spec, const std::string& default_chip, GpioLineConfig& line) {
  const std::string original(spec);
  line.active_low = spec.starts_with('!');
  if (line.active_low) spec.remove_prefix(1);
  line.chip = default_chip;
  if (const auto colon = spec.find(':'); colon != std::string_view::npos) {
    line.chip = std::string(spec.substr(0, colon));
    spec.remove_prefix(colon + 1);
    if (line.chip.empty())
      throw std::invalid_argument(fmt::format("gpio line spec '{}': empty chip name", original));
  }
  if (spec.empty())
    throw std::invalid_argument(fmt::format("gpio line spec '{}': empty line", original));
  line.line_name.clear();
  line.offset = -1;
  int offset = 0;
  const auto [end, ec] = std::from_chars(spec.data(), spec.data() + spec.size(), offset);
  if (ec == std::errc{} && end == spec.data() + spec.size()) {
    if (offset < 0)
      throw std::invalid_argument(fmt::format("gpio line spec '{}': negative offset", original));
    line.offset = offset;
  } else {
    line.line_name = std::string(spec);
  }
}

GpioConfig make_gpio_config(const std::map<std::string, std::string>& line_map,
                            const std::string& default_chip) {
  GpioConfig config;
  for (const auto& [role, spec] : line_map) {
    GpioLineConfig line;
    line.role = role;
    if (!classify_role(role, line))
      throw std::invalid_argument(
          fmt::format("gpio lines: unknown role '{}' (expected interlock, estop, relay.N (1..{}), "
                      "tower.green, tower.amber, tower.red)",
                      role, kMaxRelaySlot));
    try {
      parse_line_spec(spec, default_chip, line);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("gpio lines: key '{}': {}", role, e.what()));
    }
    for (const auto& other : config.lines)
      if (other.chip == line.chip && other.line_name == line.line_name &&
          other.offset == line.offset)
        throw std::invalid_argument(
            fmt::format("gpio lines: keys '{}' and '{}' name the same line {}", other.role, role,
                        line.where()));
    config.lines.push_back(std::move(line));
  }
  return config;
}

const GpioLineConfig* find_role(const GpioConfig& config, std::string_view role) {
  for (const auto& line : config.lines)
    if (line.role == role) return &line;
  return nullptr;
}

TapRecord gpio_edge_record(const std::string& device, const GpioEdge& edge) {
  return TapRecord{tap_wall_time_s(),
                   device,
                   TapDirection::event,
                   "gpio-edge",
                   {static_cast<std::uint8_t>(edge.rising ? 1 : 0)},
                   fmt::format("role={} line={} edge={} mono_s={:.9f}", edge.role, edge.line,
                               edge.rising ? "rising" : "falling", edge.timestamp_s)};
}

TapRecord gpio_read_record(const std::string& device, const GpioLineConfig& line, bool active) {
  return TapRecord{tap_wall_time_s(),
                   device,
                   TapDirection::rx,
                   "gpio-read",
                   {static_cast<std::uint8_t>(active ? 1 : 0)},
                   fmt::format("role={} line={} active={}", line.role, line.where(), active)};
}

TapRecord gpio_write_record(const std::string& device, const GpioLineConfig& line, bool active) {
  return TapRecord{tap_wall_time_s(),
                   device,
                   TapDirection::tx,
                   "gpio-write",
                   {static_cast<std::uint8_t>(active ? 1 : 0)},
                   fmt::format("role={} line={} active={}", line.role, line.where(), active)};
}

}  // namespace station::drivers::gpio
