// Numeric CSV tables with a header row: columns by name, every error naming file, line, column.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "station/common/input_error.hpp"

namespace station {

/// The requested columns of a CSV file, as doubles, with the file line of each row.
struct CsvColumns {
  std::string path;
  std::vector<std::string> names;            ///< requested column names, in request order
  std::vector<std::vector<double>> columns;  ///< columns[c][row]
  std::vector<std::size_t> lines;            ///< 1-based file line of each row
  const std::vector<double>& operator[](std::size_t c) const { return columns[c]; }
};

/// Reads `path` (comma-separated, header row, '#' comment lines and blank lines skipped, a UTF-8
/// byte-order mark at the start ignored) and
/// returns the named columns. Throws InputError on a missing file or column, a ragged row, or a
/// cell that is not a finite number ("FILE:LINE: column 'NAME': ...").
CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& names);

/// The column names of `path`'s header row (what read_csv_columns reads as the header).
std::vector<std::string> read_csv_header(const std::string& path);

/// Throws InputError naming the first row whose value in column c does not increase.
void require_increasing(const CsvColumns& t, std::size_t c);

/// Throws InputError ("FILE:LINE: column 'NAME': what") at the first row of column c for which
/// `problem` returns a non-empty text (e.g. compensation::rate_problem).
void require_within(const CsvColumns& t, std::size_t c,
                    const std::function<std::string(double)>& problem);

}  // namespace station
