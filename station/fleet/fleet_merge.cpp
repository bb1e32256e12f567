#include "station/fleet/fleet_merge.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

namespace station::fleet {
namespace {

std::string prefixed(const std::vector<std::string_view>& cols, std::string_view prefix) {
  std::string out;
  for (const auto& c : cols)
    fmt::format_to(std::back_inserter(out), "{}{}{}", out.empty() ? "" : ", ", prefix, c);
  return out;
}

std::vector<std::string_view> non_key(const FleetTable& t) {
  std::vector<std::string_view> out;
  const auto key = split_columns(t.key);
  for (const auto& c : split_columns(t.columns))
    if (std::find(key.begin(), key.end(), c) == key.end()) out.push_back(c);
  return out;
}

/// An item's own row: it carries the station's revision of the item (`rev`).
bool has_rev(const FleetTable& t) {
  const auto cols = split_columns(t.columns);
  return std::find(cols.begin(), cols.end(), "rev") != cols.end();
}

// INSERT ... ON CONFLICT (postgresql.org/docs/15/sql-insert.html): DO NOTHING for appended rows;
// DO UPDATE only WHERE the stored row IS DISTINCT FROM the incoming one, so an identical resend
// writes nothing.
std::string merge_sql(const FleetTable& t) {
  const std::string insert =
      fmt::format("INSERT INTO {0} AS t ({1}) SELECT {1} FROM stage_{0} ", t.name, t.columns);
  if (t.merge == Merge::append) return insert + fmt::format("ON CONFLICT ({}) DO NOTHING", t.key);
  const auto rest = non_key(t);
  // An item's row carries its revision: only a higher one replaces it (an older file, restored
  // from a backup, never writes over a newer state). Its children: replaced when they differ.
  const std::string when = has_rev(t)
                               ? std::string("EXCLUDED.rev > t.rev")
                               : fmt::format("({}) IS DISTINCT FROM ({})", prefixed(rest, "t."),
                                             prefixed(rest, "EXCLUDED."));
  return insert + fmt::format("ON CONFLICT ({}) DO UPDATE SET ({}) = ROW({}) WHERE {}", t.key,
                              prefixed(rest, ""), prefixed(rest, "EXCLUDED."), when);
}

std::string prune_sql(const FleetTable& t) {
  const auto key = split_columns(t.key);
  return fmt::format(
      "DELETE FROM {0} AS t WHERE t.run_uuid = $1 AND NOT EXISTS (SELECT 1 FROM stage_{0} AS s "
      "WHERE ({1}) = ({2}))",
      t.name, prefixed(key, "s."), prefixed(key, "t."));
}

}  // namespace

void append_copy_row(const Statement& st, std::string& out) {
  const int n = st.column_count();
  for (int c = 0; c < n; ++c) {
    if (c > 0) out += '\t';
    switch (st.column_type(c)) {
      case SQLITE_NULL:
        append_copy_field(out, std::nullopt);
        break;
      case SQLITE_INTEGER:
        fmt::format_to(std::back_inserter(out), "{}", st.column_int(c));
        break;
      case SQLITE_FLOAT:
        fmt::format_to(std::back_inserter(out), "{}", st.column_double(c));
        break;
      default: {
        const std::string text = st.column_text(c);
        append_copy_field(out, std::string_view(text));
      }
    }
  }
  out += '\n';
}

EncodedRows encode_rows(Statement& st, int watermark_col) {
  EncodedRows out;
  while (st.step()) {
    append_copy_row(st, out.data);
    if (watermark_col >= 0) {
      out.last = st.column_double(watermark_col);
      if (!out.first) out.first = out.last;
    }
    ++out.rows;
  }
  return out;
}

void stage_rows(PgConnection& pg, const FleetTable& t, const EncodedRows& rows) {
  // Made once per connection (its rows go at each commit), emptied before each use: a table
  // made and dropped in every transaction would churn the server's catalog.
  pg.exec(fmt::format(
      "CREATE TEMP TABLE IF NOT EXISTS stage_{0} ON COMMIT DELETE ROWS AS SELECT {1} FROM {0} "
      "WITH NO DATA; TRUNCATE stage_{0}",
      t.name, t.columns));
  if (rows.rows > 0) pg.copy_in(fmt::format("stage_{} ({})", t.name, t.columns), rows.data);
}

// A staged row the server already holds with other content (or, for an item, at a higher
// revision, or at the same revision with other content): the file and the server no longer
// share a past. The first such row is named by its key, with the columns that differ
// (array_to_string leaves out the NULLs of the columns that agree).
std::optional<std::string> first_diverged(PgConnection& pg, const FleetTable& t) {
  const auto key = split_columns(t.key);
  std::string on, key_text;
  for (const auto& k : key) {
    on += fmt::format("{0}s.{1} = c.{1}", on.empty() ? "" : " AND ", k);
    key_text += fmt::format("{0}'{1}=', s.{1}", key_text.empty() ? "" : ", ', ', ", k);
  }
  const auto rest = non_key(t);
  std::string which;
  for (const auto& c : rest)
    if (c != "rev")
      which += fmt::format("{0}CASE WHEN s.{1} IS DISTINCT FROM c.{1} THEN '{1}' END",
                           which.empty() ? "" : ", ", c);
  const std::string differs =
      fmt::format("({}) IS DISTINCT FROM ({})", prefixed(rest, "s."), prefixed(rest, "c."));
  const std::string when =
      has_rev(t) ? fmt::format("c.rev > s.rev OR (c.rev = s.rev AND {})", differs) : differs;
  const std::string revs = has_rev(t) ? "c.rev, s.rev" : "0, 0";
  auto r = pg.exec(fmt::format(
      "SELECT concat({3}), array_to_string(ARRAY[{4}], ', '), {5} FROM stage_{0} AS s JOIN {0} "
      "AS c ON {1} WHERE {2} LIMIT 1",
      t.name, on, when, key_text, which, revs));
  if (r.rows() == 0) return std::nullopt;
  const std::string row = fmt::format("the server's {} row ({})", t.name, r.text(0, 0));
  if (r.integer(0, 2) > r.integer(0, 3))
    return fmt::format("{} is at revision {}, this file's at {}", row, r.integer(0, 2),
                       r.integer(0, 3));
  return fmt::format("{} differs from this file's in {}", row, r.text(0, 1));
}

std::optional<std::string> station_name_taken(PgConnection& pg, const FleetTable& t,
                                              const std::string& station_uuid) {
  pg.exec(fmt::format("INSERT INTO stations (name, station_uuid) SELECT DISTINCT station, "
                      "$1::uuid FROM stage_{} ON CONFLICT (name) DO NOTHING",
                      t.name),
          {station_uuid});
  auto r = pg.exec(
      fmt::format("SELECT st.name, st.station_uuid, $1::uuid FROM stations AS st WHERE st.name "
                  "IN (SELECT station FROM stage_{}) AND st.station_uuid <> $1::uuid "
                  "ORDER BY 1 LIMIT 1",
                  t.name),
      {station_uuid});
  if (r.rows() == 0) return std::nullopt;
  return fmt::format(
      "station name '{}' is held on the fleet server by station identity {}, and this file is "
      "station identity {}: two stations under one [station] name would merge into one history; "
      "refused, nothing of it written (give this station its own [station] name; a station moved "
      "to a new file is released by deleting its row in the central `stations` table)",
      r.text(0, 0), r.text(0, 1), r.text(0, 2));
}

std::int64_t merge_staged(PgConnection& pg, const FleetTable& t, const std::string& run_uuid) {
  std::int64_t changed = pg.exec(merge_sql(t)).affected();
  if (t.merge == Merge::replace_set) changed += pg.exec(prune_sql(t), {run_uuid}).affected();
  return changed;
}

std::int64_t stage_and_merge(PgConnection& pg, const FleetTable& t, const EncodedRows& rows,
                             const std::string& run_uuid) {
  stage_rows(pg, t, rows);
  return merge_staged(pg, t, run_uuid);
}

}  // namespace station::fleet
