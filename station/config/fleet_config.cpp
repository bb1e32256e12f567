#include "station/config/fleet_config.hpp"

#include <fmt/format.h>
#include <libpq-fe.h>

#include <algorithm>
#include <filesystem>

#include "station/config/toml_reader.hpp"

namespace station {

// PQconninfoParse parses both URI and key=value forms as libpq will
// (postgresql.org/docs/15/libpq-connect.html#LIBPQ-CONNSTRING).
std::optional<std::string> pg_url_problem(const std::string& url) {
  if (url.empty()) return "must not be empty";
  char* err = nullptr;
  PQconninfoOption* opts = PQconninfoParse(url.c_str(), &err);
  if (opts == nullptr) {
    std::string why = err != nullptr ? err : "out of memory";
    PQfreemem(err);
    while (!why.empty() && why.back() == '\n') why.pop_back();
    return fmt::format("not a PostgreSQL connection string ({})", why);
  }
  std::optional<std::string> problem;
  for (auto* o = opts; o->keyword != nullptr; ++o) {
    const std::string_view k = o->keyword;
    if ((k == "password" || k == "sslpassword") && o->val != nullptr && *o->val != '\0')
      problem = fmt::format(
          "holds a {}: put it in a password file (password_file, libpq's passfile) or the "
          "PGPASSWORD environment variable, never in the configuration or on a command line",
          k);
  }
  PQconninfoFree(opts);
  return problem;
}

FleetConfig read_fleet_config(const TomlView& t, const std::string& path) {
  t.allow_only({"pg", "password_file", "samples", "interval_s", "timeout_s", "sslmode",
                "sslrootcert", "sslcert", "sslkey", "sslcrl"});
  FleetConfig f;
  f.pg = t.get_string("pg");
  if (auto why = pg_url_problem(f.pg)) throw t.error("pg", *why);
  const auto beside = [&path](const std::string& p) {
    return (std::filesystem::path(path).parent_path() / p).string();
  };
  if (auto p = t.opt_string("password_file")) {
    if (p->empty()) throw t.error("password_file", "must not be empty");
    f.keywords.emplace_back("passfile", beside(*p));
  }
  if (auto m = t.opt_string("sslmode")) {
    static const char* const kModes[] = {"disable", "allow",     "prefer",
                                         "require", "verify-ca", "verify-full"};
    if (std::find(std::begin(kModes), std::end(kModes), *m) == std::end(kModes))
      throw t.error("sslmode",
                    "must be disable, allow, prefer, require, verify-ca or verify-full (libpq)");
    f.keywords.emplace_back("sslmode", *m);
  }
  for (const char* k : {"sslrootcert", "sslcert", "sslkey", "sslcrl"}) {
    if (auto p = t.opt_string(k)) {
      if (p->empty()) throw t.error(k, "must not be empty");
      f.keywords.emplace_back(k, beside(*p));
    }
  }
  f.samples = t.opt_bool("samples").value_or(f.samples);
  f.interval_s = t.opt_number_in("interval_s", 0.1, 3600.0, "s").value_or(f.interval_s);
  f.timeout_s = t.opt_number_in("timeout_s", 0.5, 3600.0, "s").value_or(f.timeout_s);
  return f;
}

}  // namespace station
