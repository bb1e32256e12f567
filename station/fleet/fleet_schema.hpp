// The fleet's central schema on PostgreSQL: its migrations (schemas/fleet/*.sql, embedded), the
// version a server holds, and the rule a station follows about it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "station/fleet/pg.hpp"

namespace station::fleet {

/// The central schema version this software writes (the number of schemas/fleet/*.sql).
int fleet_schema_version();

/// The version the server holds: 0 when it has no fleet schema.
int server_schema_version(PgConnection& pg);

/// Creates or migrates the central schema (`station sync --init`), in one transaction under an
/// advisory lock so two stations initialising at once do not both migrate; first re-creates the
/// tables of the server's version it lacks (named in `recreated`). Returns the version the
/// server held before.
int init_fleet_schema(PgConnection& pg, std::vector<std::string>* recreated = nullptr);

/// The central tables a station writes that the server lacks (whatever its version row says).
std::vector<std::string> missing_fleet_tables(PgConnection& pg);

/// Why a server holding version `have` cannot take this station's `want` (empty: it can): none
/// (0), or older. A newer server is accepted (its migrations only add).
std::optional<std::string> fleet_schema_problem(int have, int want);

/// Throws PgError (one line) when the server's schema is missing or older than this station's
/// (the station would write columns the server lacks), or a table of it is missing. A newer
/// server is accepted (its migrations only add).
void require_fleet_schema(PgConnection& pg);

}  // namespace station::fleet
