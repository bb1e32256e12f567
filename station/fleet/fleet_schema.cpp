#include "station/fleet/fleet_schema.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include "schemas/fleet_migrations.hpp"
#include "station/fleet/fleet_tables.hpp"

namespace station::fleet {
namespace {

// pg_advisory_xact_lock key for schema changes: "GTCL" (the station's SQLite application_id).
constexpr long long kSchemaLockKey = 0x4754434C;
// Where `--init` builds the tables of the server's version to compare (dropped at the end of its
// transaction's work, under the same lock).
constexpr const char* kScratchSchema = "fleet_init_scratch";

}  // namespace

int fleet_schema_version() {
  return static_cast<int>(schemas::kFleetMigrations.size());
}

int server_schema_version(PgConnection& pg) {
  auto exists = pg.exec("SELECT to_regclass('fleet_schema') IS NOT NULL");
  if (exists.text(0, 0) != "t") return 0;
  auto v = pg.exec("SELECT coalesce(max(version), 0) FROM fleet_schema");
  return static_cast<int>(v.integer(0, 0));
}

namespace {

// The tables of the version the server says it holds are built in a scratch schema from the
// same migrations and compared with the server's: one the server lacks (dropped by hand, lost in
// a partial restore) is moved over from the scratch schema with its indexes and identity
// sequences (ALTER TABLE ... SET SCHEMA, postgresql.org/docs/15/sql-altertable.html), so the
// version row alone never claims a table exists. Tables the server has are left as they are.
std::vector<std::string> mend_tables(PgConnection& pg, int have) {
  const std::string target = pg.exec("SELECT quote_ident(current_schema())").text(0, 0);
  const std::string path = pg.exec("SELECT current_setting('search_path')").text(0, 0);
  pg.exec(
      fmt::format("DROP SCHEMA IF EXISTS {0} CASCADE; CREATE SCHEMA {0}; SET LOCAL "
                  "search_path = {0}",
                  kScratchSchema));
  for (int v = 0; v < std::min(have, fleet_schema_version()); ++v)
    pg.exec(schemas::kFleetMigrations[static_cast<std::size_t>(v)].second);
  pg.exec(fmt::format("SET LOCAL search_path = {}", path));
  auto missing = pg.exec(
      "SELECT s.tablename FROM pg_tables AS s WHERE s.schemaname = $1 AND "
      "to_regclass(quote_ident($2) "
      "|| '.' || quote_ident(s.tablename)) IS NULL ORDER BY 1",
      {std::string(kScratchSchema), pg.exec("SELECT current_schema()").text(0, 0)});
  std::vector<std::string> names;
  for (int i = 0; i < missing.rows(); ++i) names.push_back(missing.text(i, 0));
  for (const auto& n : names)
    pg.exec(fmt::format("ALTER TABLE {}.{} SET SCHEMA {}", kScratchSchema, n, target));
  pg.exec(fmt::format("DROP SCHEMA {} CASCADE", kScratchSchema));
  return names;
}

}  // namespace

int init_fleet_schema(PgConnection& pg, std::vector<std::string>* recreated) {
  PgTransaction tx(pg);
  pg.exec(fmt::format("SELECT pg_advisory_xact_lock({})", kSchemaLockKey));
  const int have = server_schema_version(pg);
  if (have == 0 && pg.exec("SELECT to_regclass('runs') IS NOT NULL").text(0, 0) == "t")
    throw PgError(fmt::format(
        "PostgreSQL {}: fleet_schema is missing but the fleet's tables exist: the version they "
        "are at is unknown; refusing to touch them (restore fleet_schema's rows by hand)",
        pg.where()));
  const auto mended = have > 0 ? mend_tables(pg, have) : std::vector<std::string>{};
  for (int v = have; v < fleet_schema_version(); ++v) {
    pg.exec(schemas::kFleetMigrations[static_cast<std::size_t>(v)].second);
    pg.exec("INSERT INTO fleet_schema (version) VALUES ($1)", {std::to_string(v + 1)});
  }
  tx.commit();
  if (recreated != nullptr) *recreated = mended;
  return have;
}

std::vector<std::string> missing_fleet_tables(PgConnection& pg) {
  std::string names = "{fleet_schema,stations";
  for (const auto& t : fleet_tables()) names += "," + std::string(t.name);
  auto r =
      pg.exec("SELECT t FROM unnest($1::text[]) AS t WHERE to_regclass(t) IS NULL", {names + "}"});
  std::vector<std::string> out;
  for (int i = 0; i < r.rows(); ++i) out.push_back(r.text(i, 0));
  return out;
}

std::optional<std::string> fleet_schema_problem(int have, int want) {
  if (have == 0) return "no fleet schema; create it with `station sync --init`";
  if (have < want)
    return fmt::format(
        "fleet schema version {} is older than this station's {}; refusing to forward (migrate "
        "the server with `station sync --init`)",
        have, want);
  return std::nullopt;
}

void require_fleet_schema(PgConnection& pg) {
  const int have = server_schema_version(pg);
  if (auto why = fleet_schema_problem(have, fleet_schema_version()))
    throw PgError(fmt::format("PostgreSQL {}: {}", pg.where(), *why));
  if (const auto missing = missing_fleet_tables(pg); !missing.empty())
    throw PgError(fmt::format(
        "PostgreSQL {}: fleet schema version {} but table {} missing; refusing to forward "
        "(`station sync --init` re-creates it)",
        pg.where(), have, fmt::join(missing, ", ")));
}

}  // namespace station::fleet
