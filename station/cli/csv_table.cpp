// CSV reader for the offline commands (analyze, adev): strict, one clear error per bad cell.
#include "station/cli/csv_table.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <string_view>

namespace station {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    auto cell = line.substr(start, comma == std::string_view::npos ? line.npos : comma - start);
    while (!cell.empty() && (cell.front() == ' ' || cell.front() == '"')) cell.remove_prefix(1);
    while (!cell.empty() && (cell.back() == ' ' || cell.back() == '"' || cell.back() == '\r')) {
      cell.remove_suffix(1);
    }
    cells.push_back(cell);
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

bool skippable(std::string_view line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first == std::string_view::npos || line[first] == '#';
}

double parse_cell(std::string_view cell, const std::string& where) {
  double v = 0;
  const auto* end = cell.data() + cell.size();
  const auto [ptr, ec] = std::from_chars(cell.data(), end, v);
  if (cell.empty()) throw InputError(where + ": empty cell");
  if (ec == std::errc::result_out_of_range && ptr == end) {
    throw InputError(fmt::format("{}: number out of the range of a double: '{}'", where, cell));
  }
  if (ec != std::errc{} || ptr != end) {
    throw InputError(fmt::format("{}: not a number: '{}'", where, cell));
  }
  if (!std::isfinite(v))
    throw InputError(fmt::format("{}: not a finite number: '{}'", where, cell));
  return v;
}

std::vector<std::size_t> find_columns(const std::vector<std::string_view>& header,
                                      const std::vector<std::string>& names,
                                      const std::string& path, std::size_t line_no) {
  std::vector<std::size_t> idx;
  for (const auto& name : names) {
    std::size_t found = header.size();
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) found = i;
    }
    if (found == header.size()) {
      std::string have;
      for (auto h : header) have += (have.empty() ? "" : ", ") + std::string(h);
      throw InputError(fmt::format("{}:{}: no column '{}' in the header (columns: {})", path,
                                   line_no, name, have));
    }
    idx.push_back(found);
  }
  return idx;
}

}  // namespace

CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& names) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open file", path));
  CsvColumns out{path, names, std::vector<std::vector<double>>(names.size()), {}};
  std::string line;
  std::size_t line_no = 0;
  std::vector<std::size_t> idx;
  std::size_t n_header = 0;
  while (std::getline(in, line)) {
    ++line_no;
    // A UTF-8 byte-order mark (spreadsheets write one) is not part of the first column's name.
    if (line_no == 1 && line.rfind(kUtf8Bom, 0) == 0) line.erase(0, kUtf8Bom.size());
    if (skippable(line)) continue;
    const auto cells = split(line);
    if (idx.empty()) {
      idx = find_columns(cells, names, path, line_no);
      n_header = cells.size();
      continue;
    }
    if (cells.size() != n_header) {
      throw InputError(fmt::format("{}:{}: {} cells where the header has {}", path, line_no,
                                   cells.size(), n_header));
    }
    for (std::size_t c = 0; c < idx.size(); ++c) {
      const auto where = fmt::format("{}:{}: column '{}'", path, line_no, names[c]);
      out.columns[c].push_back(parse_cell(cells[idx[c]], where));
    }
    out.lines.push_back(line_no);
  }
  if (idx.empty() && !names.empty()) throw InputError(fmt::format("{}: no header row", path));
  return out;
}

std::vector<std::string> read_csv_header(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open file", path));
  std::string line;
  for (std::size_t line_no = 1; std::getline(in, line); ++line_no) {
    if (line_no == 1 && line.rfind(kUtf8Bom, 0) == 0) line.erase(0, kUtf8Bom.size());
    if (skippable(line)) continue;
    std::vector<std::string> names;
    for (auto cell : split(line)) names.emplace_back(cell);
    return names;
  }
  throw InputError(fmt::format("{}: no header row", path));
}

void require_increasing(const CsvColumns& t, std::size_t c) {
  const auto& v = t.columns.at(c);
  for (std::size_t i = 1; i < v.size(); ++i) {
    if (!(v[i] > v[i - 1])) {
      throw InputError(fmt::format("{}:{}: column '{}': {} does not increase (previous row {})",
                                   t.path, t.lines[i], t.names[c], v[i], v[i - 1]));
    }
  }
}

void require_within(const CsvColumns& t, std::size_t c,
                    const std::function<std::string(double)>& problem) {
  const auto& v = t.columns.at(c);
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (const std::string p = problem(v[i]); !p.empty()) {
      throw InputError(fmt::format("{}:{}: column '{}': {}", t.path, t.lines[i], t.names[c], p));
    }
  }
}

}  // namespace station
