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

// INSERT ... ON CONFLICT (postgresql.org/docs/15/sql-insert.html): DO NOTHING for appended rows;
// DO UPDATE only WHERE the stored row IS DISTINCT FROM the incoming one, so an identical resend
// writes nothing.
std::string merge_sql(const FleetTable& t) {
  const std::string insert =
      fmt::format("INSERT INTO {0} AS t ({1}) SELECT {1} FROM stage_{0} ", t.name, t.columns);
  if (t.merge == Merge::append) return insert + fmt::format("ON CONFLICT ({}) DO NOTHING", t.key);
  const auto rest = non_key(t);
  return insert +
         fmt::format(
             "ON CONFLICT ({}) DO UPDATE SET ({}) = ROW({}) WHERE ({}) IS DISTINCT FROM ({})",
             t.key, prefixed(rest, ""), prefixed(rest, "EXCLUDED."), prefixed(rest, "t."),
             prefixed(rest, "EXCLUDED."));
}

std::string prune_sql(const FleetTable& t) {
  const auto key = split_columns(t.key);
  return fmt::format(
      "DELETE FROM {0} AS t WHERE t.run_uuid = $1 AND NOT EXISTS (SELECT 1 FROM stage_{0} AS s "
      "WHERE ({1}) = ({2}))",
      t.name, prefixed(key, "s."), prefixed(key, "t."));
}

}  // namespace

EncodedRows encode_rows(Statement& st, int watermark_col) {
  EncodedRows out;
  while (st.step()) {
    const int n = st.column_count();
    for (int c = 0; c < n; ++c) {
      if (c > 0) out.data += '\t';
      switch (st.column_type(c)) {
        case SQLITE_NULL:
          append_copy_field(out.data, std::nullopt);
          break;
        case SQLITE_INTEGER:
          out.data += std::to_string(st.column_int(c));
          break;
        case SQLITE_FLOAT:
          out.data += fmt::format("{}", st.column_double(c));
          break;
        default: {
          const std::string text = st.column_text(c);
          append_copy_field(out.data, std::string_view(text));
        }
      }
    }
    out.data += '\n';
    if (watermark_col >= 0) out.last = st.column_double(watermark_col);
    ++out.rows;
  }
  return out;
}

std::int64_t stage_and_merge(PgConnection& pg, const FleetTable& t, const EncodedRows& rows,
                             const std::string& run_uuid) {
  pg.exec(fmt::format(
      "CREATE TEMP TABLE IF NOT EXISTS stage_{0} ON COMMIT DROP AS SELECT {1} FROM {0} WITH NO "
      "DATA; TRUNCATE stage_{0}",
      t.name, t.columns));
  if (rows.rows > 0) pg.copy_in(fmt::format("stage_{} ({})", t.name, t.columns), rows.data);
  std::int64_t changed = 0;
  if (rows.rows > 0) {
    auto r = pg.exec(merge_sql(t));
    changed = r.affected();
  }
  if (t.merge == Merge::replace_set) changed += pg.exec(prune_sql(t), {run_uuid}).affected();
  return changed;
}

}  // namespace station::fleet
