// Strict TOML getters: every error is "FILE:LINE: key 'a.b': what".
#include "station/config/toml_reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace station {
namespace {

InputError parse_failure(const toml::parse_error& e, const std::string& file) {
  return InputError(fmt::format("{}:{}:{}: TOML syntax: {}", file, e.source().begin.line,
                                e.source().begin.column, e.description()));
}

}  // namespace

toml::table TomlView::parse_file(const std::string& path) {
  try {
    return toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    if (e.source().begin.line == 0) throw InputError(fmt::format("{}: {}", path, e.description()));
    throw parse_failure(e, path);
  }
}

toml::table TomlView::parse_text(std::string_view text, const std::string& file) {
  try {
    return toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    throw parse_failure(e, file);
  }
}

std::string TomlView::full_key(std::string_view key) const {
  return prefix_.empty() ? std::string(key) : prefix_ + "." + std::string(key);
}

const toml::node* TomlView::find(std::string_view key) const {
  return table_->get(key);
}

std::size_t TomlView::line_of(std::string_view key) const {
  const toml::node* n = find(key);
  const auto line = n != nullptr ? n->source().begin.line : table_->source().begin.line;
  return line;
}

InputError TomlView::error(std::string_view key, std::string_view what) const {
  return InputError(fmt::format("{}:{}: key '{}': {}", file_, line_of(key), full_key(key), what));
}

std::optional<std::string> TomlView::opt_string(std::string_view key) const {
  const toml::node* n = find(key);
  if (n == nullptr) return std::nullopt;
  if (!n->is_string()) throw error(key, "expected a string");
  return n->value<std::string>();
}

std::optional<double> TomlView::opt_number(std::string_view key) const {
  const toml::node* n = find(key);
  if (n == nullptr) return std::nullopt;
  if (!n->is_number()) throw error(key, "expected a number");
  // toml++ converts an integer to double only when exact: 9223372036854775807 gives no value
  // (read as 0 before), so integers are converted here.
  const double v =
      n->is_integer() ? static_cast<double>(*n->value<std::int64_t>()) : *n->value<double>();
  // TOML allows inf and nan; no setting of ours means either.
  if (!std::isfinite(v)) throw error(key, "must be a finite number");
  return v;
}

std::optional<long long> TomlView::opt_integer(std::string_view key) const {
  const toml::node* n = find(key);
  if (n == nullptr) return std::nullopt;
  if (!n->is_integer()) throw error(key, "expected an integer");
  return n->value<long long>();
}

std::optional<double> TomlView::opt_number_in(std::string_view key, double lo, double hi,
                                              std::string_view unit) const {
  const auto v = opt_number(key);
  if (v && (*v < lo || *v > hi)) {
    throw error(key,
                fmt::format("{} is outside {}..{}{}{}", *v, lo, hi, unit.empty() ? "" : " ", unit));
  }
  return v;
}

std::optional<long long> TomlView::opt_integer_in(std::string_view key, long long lo,
                                                  long long hi) const {
  const auto v = opt_integer(key);
  if (v && (*v < lo || *v > hi)) throw error(key, fmt::format("{} is outside {}..{}", *v, lo, hi));
  return v;
}

std::optional<bool> TomlView::opt_bool(std::string_view key) const {
  const toml::node* n = find(key);
  if (n == nullptr) return std::nullopt;
  if (!n->is_boolean()) throw error(key, "expected true or false");
  return n->value<bool>();
}

std::string TomlView::get_string(std::string_view key) const {
  auto v = opt_string(key);
  if (!v) throw error(key, "missing (required string)");
  return *v;
}

double TomlView::get_number(std::string_view key) const {
  auto v = opt_number(key);
  if (!v) throw error(key, "missing (required number)");
  return *v;
}

long long TomlView::get_integer(std::string_view key) const {
  auto v = opt_integer(key);
  if (!v) throw error(key, "missing (required integer)");
  return *v;
}

std::optional<TomlView> TomlView::opt_table(std::string_view key) const {
  const toml::node* n = find(key);
  if (n == nullptr) return std::nullopt;
  if (!n->is_table()) throw error(key, "expected a table");
  return TomlView(*n->as_table(), file_, full_key(key));
}

std::vector<double> TomlView::number_array_in(std::string_view key, double lo, double hi,
                                              std::string_view unit,
                                              std::size_t max_count) const {
  std::vector<double> out;
  const toml::node* n = find(key);
  if (n == nullptr) return out;
  const toml::array* arr = n->as_array();
  if (arr == nullptr) throw error(key, "expected an array of numbers");
  if (arr->size() > max_count)
    throw error(key, fmt::format("{} entries, at most {}", arr->size(), max_count));
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::node& e = (*arr)[i];
    if (!e.is_number()) throw error(key, fmt::format("entry {} is not a number", i));
    const double v =
        e.is_integer() ? static_cast<double>(*e.value<std::int64_t>()) : *e.value<double>();
    if (!std::isfinite(v) || v < lo || v > hi) {
      throw error(key, fmt::format("entry {}: {} is outside {}..{}{}{}", i, v, lo, hi,
                                   unit.empty() ? "" : " ", unit));
    }
    out.push_back(v);
  }
  return out;
}

std::vector<TomlView> TomlView::table_array(std::string_view key) const {
  std::vector<TomlView> out;
  const toml::node* n = find(key);
  if (n == nullptr) return out;
  const toml::array* arr = n->as_array();
  if (arr == nullptr) throw error(key, "expected an array of tables ([[" + full_key(key) + "]])");
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::table* t = (*arr)[i].as_table();
    if (t == nullptr) throw error(key, fmt::format("entry {} is not a table", i));
    out.emplace_back(*t, file_, fmt::format("{}[{}]", full_key(key), i));
  }
  return out;
}

void TomlView::allow_only(std::initializer_list<std::string_view> allowed) const {
  for (const auto& [k, node] : *table_) {
    const std::string_view key = k.str();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      throw InputError(fmt::format("{}:{}: key '{}': unknown key (allowed here: {})", file_,
                                   node.source().begin.line, full_key(key), list));
    }
  }
}

}  // namespace station
