// How one table's rows travel: SQLite rows encoded as COPY text, staged in a temporary table,
// merged into the central table by the table's Merge rule (fleet_tables.hpp). SQL generated from
// the table's column lists, so a column is named once.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "station/fleet/fleet_tables.hpp"
#include "station/fleet/pg.hpp"
#include "station/store/sqlite.hpp"

namespace station::fleet {

/// Rows encoded for COPY and the value of one column in the last row (a watermark).
struct EncodedRows {
  std::string data;
  std::int64_t rows = 0;
  std::optional<double> first, last;  ///< column `watermark_col` of the first and last rows
};

/// Steps `st` to the end, encoding every row. Values keep their exact value: integers as
/// decimal, reals as the shortest text that reads back to the same double (fmt "{}"), text as
/// is. `watermark_col` < 0: none.
EncodedRows encode_rows(Statement& st, int watermark_col = -1);
/// Appends the row `st` stands on to `out` as one COPY text line, encoded as encode_rows does.
void append_copy_row(const Statement& st, std::string& out);

/// Copies `rows` into the transaction's staging table for `t` (emptied first).
void stage_rows(PgConnection& pg, const FleetTable& t, const EncodedRows& rows);
/// The first staged row the server holds with other content — or, for an item's own row (it has
/// `rev`), at a higher revision or at the same one with other content: the station's file and
/// the server have parted (a restored backup, a copied file, a row edited on the server). Says
/// which: "the server's events row (run_uuid=…, local_id=12) differs from this file's in
/// message"; empty when none.
std::optional<std::string> first_diverged(PgConnection& pg, const FleetTable& t);
/// Binds each station name of the staged item rows of `t` to `station_uuid` where the name is
/// free (central `stations`); says which name another station identity holds, empty when none.
std::optional<std::string> station_name_taken(PgConnection& pg, const FleetTable& t,
                                              const std::string& station_uuid);
/// Merges the staged rows into `t` by its Merge rule inside the caller's transaction; returns
/// the rows the server inserted or changed. `run_uuid` scopes a replace_set's deletions.
std::int64_t merge_staged(PgConnection& pg, const FleetTable& t, const std::string& run_uuid);
/// stage_rows then merge_staged.
std::int64_t stage_and_merge(PgConnection& pg, const FleetTable& t, const EncodedRows& rows,
                             const std::string& run_uuid);

}  // namespace station::fleet
