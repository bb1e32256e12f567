// Test helper: a throw-away PostgreSQL 15 server (Debian postgresql-15): initdb into a temporary
// directory, pg_ctl start listening on a Unix socket in that directory only (no TCP port to
// collide with), stopped and removed at the end. Run as the `postgres` user (runuser) when the
// test runs as root: the server refuses to run as root. Tests skip, with a message, when the
// server binaries are missing.
#pragma once

#include <fmt/format.h>
#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace station::testing_support {

inline constexpr const char* kPgBin = "/usr/lib/postgresql/15/bin";

class ThrowawayPostgres {
 public:
  /// Empty when the server can be started; the reason otherwise (the test skips).
  static std::string unavailable() {
    if (!std::filesystem::exists(std::string(kPgBin) + "/initdb"))
      return "PostgreSQL 15 server binaries not installed (Debian postgresql-15)";
    if (geteuid() == 0 && getpwnam("postgres") == nullptr)
      return "running as root and no 'postgres' user to run the server as";
    return {};
  }

  ThrowawayPostgres() {
    char tmpl[] = "/tmp/station-pg-XXXXXX";
    dir_ = mkdtemp(tmpl);
    if (geteuid() == 0) {
      const passwd* pw = getpwnam("postgres");
      if (chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) throw std::runtime_error("chown");
      as_user_ = "runuser -u postgres -- ";
    }
    run(
        fmt::format("{}{}/initdb -D {}/data -A trust -U station -E UTF8 --locale=C --no-sync "
                    ">{}/initdb.log 2>&1",
                    as_user_, kPgBin, dir_, dir_));
    start();
  }
  ~ThrowawayPostgres() {
    std::system(fmt::format("{}{}/pg_ctl -D {}/data -m immediate stop >/dev/null 2>&1", as_user_,
                            kPgBin, dir_)
                    .c_str());
    std::filesystem::remove_all(dir_);
  }
  ThrowawayPostgres(const ThrowawayPostgres&) = delete;
  ThrowawayPostgres& operator=(const ThrowawayPostgres&) = delete;

  /// Starts (again) and waits until it accepts connections.
  void start() {
    run(
        fmt::format("{}{}/pg_ctl -D {}/data -l {}/server.log -w -t 60 -o \"-c "
                    "listen_addresses='' -c unix_socket_directories={} -c fsync=off -c "
                    "full_page_writes=off\" start >/dev/null",
                    as_user_, kPgBin, dir_, dir_, dir_));
  }
  /// Stops: `fast` disconnects clients and shuts down cleanly (pg_ctl -m fast).
  void stop() {
    run(fmt::format("{}{}/pg_ctl -D {}/data -m fast -w stop >/dev/null", as_user_, kPgBin, dir_));
  }
  /// A libpq URL for database `db` (created by create_db; "postgres" always exists).
  std::string url(const std::string& db = "postgres") const {
    return fmt::format("postgresql:///{}?host={}&user=station", db, dir_);
  }
  void create_db(const std::string& db) {
    run(fmt::format("{}/psql -X -q -h {} -U station -d postgres -c 'CREATE DATABASE {}'", kPgBin,
                    dir_, db));
  }
  /// Runs psql with `sql`, returns its unaligned output.
  std::string psql(const std::string& db, const std::string& sql) const {
    const std::string out = dir_ + "/psql.out";
    run(fmt::format("{}/psql -X -q -A -t -h {} -U station -d {} -c \"{}\" >{}", kPgBin, dir_, db,
                    sql, out));
    std::string text;
    if (FILE* f = std::fopen(out.c_str(), "r")) {
      char buf[4096];
      std::size_t n;
      while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
      std::fclose(f);
    }
    while (!text.empty() && text.back() == '\n') text.pop_back();
    return text;
  }
  const std::string& dir() const { return dir_; }

 private:
  static void run(const std::string& cmd) {
    if (std::system(cmd.c_str()) != 0) throw std::runtime_error("failed: " + cmd);
  }
  std::string dir_, as_user_;
};

}  // namespace station::testing_support
