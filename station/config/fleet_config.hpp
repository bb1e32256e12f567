// [fleet]: where a station forwards its record (station/fleet/). Credentials never live in the
// configuration: a password in the URL is refused; libpq reads it from `password_file` (its
// passfile) or the PGPASSWORD environment variable.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace station {

class TomlView;

struct FleetConfig {
  std::string pg;  ///< libpq connection URI or key=value string, without a password
  /// libpq keywords passed through as given: passfile (from password_file, resolved beside the
  /// configuration), sslmode, sslrootcert, sslcert, sslkey, sslcrl (the same paths resolved).
  std::vector<std::pair<std::string, std::string>> keywords;
  bool samples = false;     ///< forward the 1 Hz samples as well
  double interval_s = 5.0;  ///< pause between passes when nothing is pending, s
  /// The longest one server call may take, s: the server's statement_timeout; the station gives
  /// up a little later (PgTarget::call_timeout_s), cancels, reconnects after a back-off.
  double timeout_s = 60.0;
};

/// Why `url` cannot be used (does not parse, or holds a password), empty when it can.
std::optional<std::string> pg_url_problem(const std::string& url);

/// Reads [fleet]; `path` is the configuration file (relative paths are beside it).
FleetConfig read_fleet_config(const TomlView& t, const std::string& path);

}  // namespace station
