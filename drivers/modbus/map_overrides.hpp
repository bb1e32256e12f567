// Point-by-point overrides of a register map (what the station config supplies), and the
// parsers for the enum spellings a config file uses. Errors throw std::invalid_argument.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/modbus/register_map.hpp"

namespace station::drivers::modbus {

/// Changes to one existing point; unset fields keep the preset's value.
struct PointOverride {
  std::string name;                        ///< point to change; must exist in the map
  std::optional<std::uint16_t> address{};  ///< register number as the manual lists it
  std::optional<PointType> type{};         ///< int16 / uint16 / float32
  std::optional<double> scale{};           ///< engineering value per raw count, non-zero
  std::optional<WordOrder> order{};        ///< float32 word order
  std::optional<FunctionCode> function{};  ///< 3 or 4
  std::optional<int> unit_id{};            ///< 0..247
  std::optional<bool> one_based{};         ///< manual numbering
  std::optional<Access> access{};          ///< ro / rw
};

/// Applies overrides in order; throws std::invalid_argument naming the point and field.
void apply_overrides(RegisterMap& map, const std::vector<PointOverride>& overrides);

/// "int16" | "uint16" | "float32"; throws std::invalid_argument otherwise.
PointType parse_point_type(std::string_view s);
/// "ABCD" | "CDAB" (case-insensitive); throws std::invalid_argument otherwise.
WordOrder parse_word_order(std::string_view s);
/// A unit's float word order as its panel names it (TestEquity F4T manual p. 14, "Modbus Word
/// Order: Low High, High Low"): "low_high" = low word first (CDAB), "high_low" (ABCD); throws
/// std::invalid_argument otherwise.
WordOrder parse_float_word_order(std::string_view s);
/// "low_high" or "high_low".
const char* float_word_order_name(WordOrder order);
/// Gives every float32 point of `map` the word order `order`; returns how many points it set.
int set_float_word_order(RegisterMap& map, WordOrder order);
/// "3" | "holding" | "4" | "input"; throws std::invalid_argument otherwise.
FunctionCode parse_function_code(std::string_view s);
/// "ro" | "rw"; throws std::invalid_argument otherwise.
Access parse_access(std::string_view s);

}  // namespace station::drivers::modbus
