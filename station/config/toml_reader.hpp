// Strict reading of TOML files (station config, protocols): typed getters whose errors name the
// file, the line and the full key, and a check that rejects keys nobody reads.
#pragma once

#include <toml++/toml.h>

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

#include "station/common/input_error.hpp"

namespace station {

/// A TOML table together with the file and key prefix it came from.
class TomlView {
 public:
  TomlView(const toml::table& table, std::string file, std::string prefix = {})
      : table_(&table), file_(std::move(file)), prefix_(std::move(prefix)) {}

  /// Parses a whole file; throws InputError with the parser's line and column.
  static toml::table parse_file(const std::string& path);
  /// Parses text labelled as `file`; throws InputError as parse_file.
  static toml::table parse_text(std::string_view text, const std::string& file);

  std::optional<std::string> opt_string(std::string_view key) const;
  std::optional<double> opt_number(std::string_view key) const;
  std::optional<long long> opt_integer(std::string_view key) const;
  std::optional<bool> opt_bool(std::string_view key) const;
  /// opt_number, and a value outside [lo, hi] throws "must be LO..HI UNIT" at the key.
  std::optional<double> opt_number_in(std::string_view key, double lo, double hi,
                                      std::string_view unit) const;
  /// opt_integer, and a value outside [lo, hi] throws "must be LO..HI" at the key (checked
  /// before any narrowing, so 2^32 + 1 is not read as 1).
  std::optional<long long> opt_integer_in(std::string_view key, long long lo, long long hi) const;
  std::string get_string(std::string_view key) const;
  double get_number(std::string_view key) const;
  long long get_integer(std::string_view key) const;

  /// Array of numbers `key` (empty when absent), each finite and within [lo, hi], at most
  /// `max_count` of them; throws naming the entry ("entry 2: 400 is outside 0..300 deg/s").
  std::vector<double> number_array_in(std::string_view key, double lo, double hi,
                                      std::string_view unit, std::size_t max_count) const;
  /// Sub-table `key` (empty when absent); throws when present with another type.
  std::optional<TomlView> opt_table(std::string_view key) const;
  /// Array of tables `key` ([[key]] entries), each as a view "key[i]".
  std::vector<TomlView> table_array(std::string_view key) const;

  /// Throws InputError naming the first key not in `allowed`.
  void allow_only(std::initializer_list<std::string_view> allowed) const;

  /// InputError for `key` at its line (or the table's line if absent).
  [[nodiscard]] InputError error(std::string_view key, std::string_view what) const;
  /// Full dotted key name.
  std::string full_key(std::string_view key) const;
  const std::string& file() const { return file_; }
  const toml::table& table() const { return *table_; }
  /// Line of `key` (or of the table when absent).
  std::size_t line_of(std::string_view key) const;

 private:
  const toml::node* find(std::string_view key) const;

  const toml::table* table_;
  std::string file_;
  std::string prefix_;
};

}  // namespace station
