#include "station/fleet/fleet_schema.hpp"

#include <fmt/format.h>

#include "schemas/fleet_migrations.hpp"

namespace station::fleet {
namespace {

// pg_advisory_xact_lock key for schema changes: "GTCL" (the station's SQLite application_id).
constexpr long long kSchemaLockKey = 0x4754434C;

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

int init_fleet_schema(PgConnection& pg) {
  PgTransaction tx(pg);
  pg.exec(fmt::format("SELECT pg_advisory_xact_lock({})", kSchemaLockKey));
  const int have = server_schema_version(pg);
  for (int v = have; v < fleet_schema_version(); ++v) {
    pg.exec(schemas::kFleetMigrations[static_cast<std::size_t>(v)].second);
    pg.exec("INSERT INTO fleet_schema (version) VALUES ($1)", {std::to_string(v + 1)});
  }
  tx.commit();
  return have;
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
  if (auto why = fleet_schema_problem(server_schema_version(pg), fleet_schema_version()))
    throw PgError(fmt::format("PostgreSQL {}: {}", pg.where(), *why));
}

}  // namespace station::fleet
