// A limit as data: a closed interval, either end open; read from a part file, stored as JSON.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>

namespace station {

class TomlView;  // station/config/toml_reader.hpp: toml++ only where a file is read

/// A closed interval; either end may be open (absent).
struct LimitRange {
  std::optional<double> min, max;
};

/// Reads the range table `key` ({min, max}) of `part`; empty when absent. Throws InputError
/// naming the key (neither end, min above max, an unknown key).
LimitRange read_range(const TomlView& part, std::string_view key);
nlohmann::json range_json(const LimitRange& r);
/// The range `key` of a stored object; empty when absent.
LimitRange range_from_json(const nlohmann::json& j, const char* key);

}  // namespace station
