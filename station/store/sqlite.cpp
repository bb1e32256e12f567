// SQLite RAII wrappers; every C error code is translated here, with the statement text.
#include "station/store/sqlite.hpp"

#include <fmt/format.h>

#include <ctime>
#include <filesystem>

#include "schemas/migrations.hpp"
#include "station/common/input_error.hpp"
#include "station/store/database_access.hpp"

namespace station {

Statement::Statement(sqlite3* db, std::string_view sql, std::string db_path)
    : db_(db), db_path_(std::move(db_path)) {
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db, sql.data(), static_cast<int>(sql.size()), &raw, nullptr) !=
      SQLITE_OK) {
    throw SqliteError(
        fmt::format("{}: cannot prepare '{}': {}", db_path_, sql, sqlite3_errmsg(db)));
  }
  stmt_.reset(raw);
}

void Statement::fail(const char* what) const {
  throw SqliteError(fmt::format("{}: {} '{}': {}", db_path_, what, sqlite3_sql(stmt_.get()),
                                sqlite3_errmsg(db_)));
}

Statement& Statement::bind(int i, double v) {
  if (sqlite3_bind_double(stmt_.get(), i, v) != SQLITE_OK) fail("bind");
  return *this;
}

Statement& Statement::bind(int i, std::int64_t v) {
  if (sqlite3_bind_int64(stmt_.get(), i, v) != SQLITE_OK) fail("bind");
  return *this;
}

Statement& Statement::bind(int i, std::string_view v) {
  if (sqlite3_bind_text(stmt_.get(), i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT) !=
      SQLITE_OK) {
    fail("bind");
  }
  return *this;
}

Statement& Statement::bind(int i, std::optional<double> v) {
  return v ? bind(i, *v) : bind_null(i);
}

Statement& Statement::bind_null(int i) {
  if (sqlite3_bind_null(stmt_.get(), i) != SQLITE_OK) fail("bind");
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(stmt_.get());
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  fail("step");
}

void Statement::reset() {
  sqlite3_reset(stmt_.get());
  sqlite3_clear_bindings(stmt_.get());
}

std::string Statement::column_text(int c) const {
  const auto* p = sqlite3_column_text(stmt_.get(), c);
  return p != nullptr ? std::string(reinterpret_cast<const char*>(p)) : std::string();
}

Database::Database(const std::string& path, OpenMode mode) : path_(path), mode_(mode) {
  DatabaseAccess access = claim_database_file(path, mode);
  hold_ = std::move(access.hold);
  const bool immutable = mode == OpenMode::read_only && access.read == ReadWay::immutable;
  if (immutable) stamp_ = access.stamp;
  const bool leave_nothing = mode == OpenMode::read_only && access.read == ReadWay::leave_nothing;
  const int flags = mode == OpenMode::create     ? SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE
                    : mode == OpenMode::existing ? SQLITE_OPEN_READWRITE
                    : leave_nothing              ? SQLITE_OPEN_READWRITE  // query_only: below
                    : immutable                  ? SQLITE_OPEN_READONLY | SQLITE_OPEN_URI
                                                 : SQLITE_OPEN_READONLY;
  const std::string name = immutable ? immutable_uri(path) : path;
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(name.c_str(), &raw, flags, nullptr);
  db_.reset(raw);
  if (rc != SQLITE_OK) {
    throw SqliteError(fmt::format("{}: cannot open{}: {}", path,
                                  mode == OpenMode::create ? "" : " (it must exist)",
                                  raw != nullptr ? sqlite3_errmsg(raw) : sqlite3_errstr(rc)));
  }
  // Every wait on a lock is bounded (5 s).
  sqlite3_busy_timeout(db_.get(), 5000);
  // A reader changes nothing, whichever way it opened the file (database_access.hpp).
  if (mode == OpenMode::read_only) exec("PRAGMA query_only=ON;");
  // Nothing is written to a file before it passes the check (a corrupt record must not grow).
  quick_check();
  // Whose file it is, before any PRAGMA that writes (journal_mode=WAL, a migration's copy).
  if (identify_empty() && mode != OpenMode::create) {
    throw SqliteError(
        fmt::format("{}: not a station database (empty, or schema version 0); "
                    "nothing was written to it",
                    path_));
  }
  if (mode == OpenMode::read_only) return;
  // WAL with synchronous=NORMAL: a commit survives the process being killed at any instant (only
  // an OS crash can lose the last commits; SQLite docs, "Write-Ahead Logging", PRAGMA synchronous).
  exec("PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL; PRAGMA foreign_keys=ON;");
}

void Database::check_unchanged() const {
  if (!stamp_) return;
  // A -wal or -shm now, even one already there when the stamp was taken: a writer is at work.
  const FileStamp now = stamp_of(path_);
  if (now == *stamp_ && !now.logs) return;
  throw InputError(
      fmt::format("{}: the database changed while it was read (a writer began on it); nothing was "
                  "output: retry",
                  path_));
}

void Database::quick_check() {
  // quick_check is integrity_check without the index-content cross-checks: O(N) in the file
  // size, well under a second for a 13 h, 16-gyro run (sqlite.org/pragma.html#pragma_quick_check).
  std::string verdict;
  try {
    auto st = prepare("PRAGMA quick_check(1)");
    verdict = st.step() ? st.column_text(0) : "no answer";
  } catch (const SqliteError&) {
    throw SqliteError(
        fmt::format("{}: not a readable station database ({}); nothing was written "
                    "to it",
                    path_, sqlite3_errmsg(db_.get())));
  }
  if (verdict != "ok") {
    throw SqliteError(fmt::format(
        "{}: the database is corrupt (PRAGMA quick_check: {}); nothing was written to it", path_,
        verdict));
  }
}

bool Database::identify_empty() {
  auto count = prepare("SELECT count(*) FROM sqlite_master");
  count.step();
  const std::int64_t objects = count.column_int(0);
  auto app = prepare("PRAGMA application_id");
  app.step();
  const auto app_id = static_cast<std::int32_t>(app.column_int(0));
  const int version = schema_version();
  if (app_id == kStationApplicationId) return false;
  const auto foreign = [&](const std::string& why) {
    return SqliteError(
        fmt::format("{}: not a station database ({}); nothing was written to it", path_, why));
  };
  if (app_id != 0)
    throw foreign(fmt::format("its application_id is 0x{:08X}, another program's",
                              static_cast<std::uint32_t>(app_id)));
  if (objects == 0 && version == 0) return true;  // a new, empty database
  // Written before the application_id was set: the schema version and the station's tables.
  auto tables = prepare(
      "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name IN "
      "('runs', 'run_slots', 'samples', 'events', 'gyros')");
  tables.step();
  const int known = static_cast<int>(schemas::kMigrations.size());
  if (version >= 1 && version <= known && tables.column_int(0) == 5) return false;
  if (version > known && tables.column_int(0) == 5) return false;  // newer: migrate() says so
  auto names = prepare(
      "SELECT group_concat(name, ', ') FROM (SELECT name FROM sqlite_master WHERE type = "
      "'table' ORDER BY name LIMIT 6)");
  names.step();
  throw foreign(fmt::format("schema version {}, tables: {}", version,
                            names.column_is_null(0) ? "none" : names.column_text(0)));
}

void Database::exec(std::string_view sql) {
  char* err = nullptr;
  const std::string text(sql);
  if (sqlite3_exec(db_.get(), text.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string msg = err != nullptr ? err : "unknown error";
    sqlite3_free(err);
    throw SqliteError(fmt::format("{}: {}", path_, msg));
  }
}

int Database::schema_version() {
  auto st = prepare("PRAGMA user_version");
  st.step();
  return static_cast<int>(st.column_int(0));
}

void Database::migrate() {
  const int known = static_cast<int>(schemas::kMigrations.size());
  const int have = check_schema_version(schema_version(), known);
  if (have == known) {  // the common case: no write lock needed
    if (mode_ != OpenMode::read_only && have > 0) stamp_application_id();
    return;
  }
  if (mode_ != OpenMode::create && have == 0) {
    throw SqliteError(
        fmt::format("{}: not a station database (empty, or schema version 0)", path_));
  }
  if (mode_ == OpenMode::read_only) {
    throw SqliteError(fmt::format(
        "{}: schema version {} is older than this software ({}); a writing command (station run, "
        "fit, release or verify) migrates it",
        path_, have, known));
  }
  backup_before_migrating(have);
  // Foreign keys off around the migrations: a migration may rebuild a table (SQLite's
  // "generalized ALTER TABLE" procedure, lang_altertable.html section 7). The pragma is a no-op
  // inside a transaction, so it is set before BEGIN and restored after.
  exec("PRAGMA foreign_keys=OFF");
  try {
    // Version check and migrations in one write transaction: two processes opening a new file at
    // once (a daemon and `station fit`) must not both migrate it.
    Transaction tx(*this);
    for (int v = check_schema_version(schema_version(), known); v < known; ++v) {
      exec(schemas::kMigrations[static_cast<std::size_t>(v)].second);
      exec(fmt::format("PRAGMA user_version = {}", v + 1));
    }
    exec(fmt::format("PRAGMA application_id = {}", kStationApplicationId));
    auto fk = prepare("PRAGMA foreign_key_check");
    if (fk.step()) {
      throw SqliteError(fmt::format("{}: migration left a foreign key violation in table '{}'",
                                    path_, fk.column_text(0)));
    }
    tx.commit();
  } catch (...) {
    exec("PRAGMA foreign_keys=ON");
    throw;
  }
  exec("PRAGMA foreign_keys=ON");
}

// A copy of the database as the older software left it, before a migration changes it (a
// package upgrade): `PATH.schema-vN.YYYYMMDDTHHMMSSZ.bak`, written with VACUUM INTO
// (sqlite.org/lang_vacuum.html, "VACUUM INTO": a consistent, compacted copy taken inside a read
// transaction) to `NAME.tmp`, then renamed, so a copy under its final name is always whole (a full
// disk or a kill mid-copy leaves at most the .tmp, removed on the next attempt). Each migration
// gets its own copy. No copy, no migration: the error says why.
void Database::backup_before_migrating(int have) {
  if (have == 0 || path_.empty() || path_ == ":memory:") return;
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &utc);
  const std::string copy = fmt::format("{}.schema-v{}.{}.bak", path_, have, stamp);
  const std::string tmp = copy + ".tmp";
  std::error_code ec;
  std::filesystem::remove(tmp, ec);
  try {
    auto st = prepare("VACUUM INTO ?1");
    st.bind(1, tmp);
    st.step();
  } catch (const SqliteError& e) {
    std::filesystem::remove(tmp, ec);
    throw SqliteError(fmt::format(
        "{}: not migrated from schema version {}: the copy {} could not be written ({})", path_,
        have, copy, e.what()));
  }
  std::filesystem::rename(tmp, copy, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw SqliteError(fmt::format("{}: not migrated from schema version {}: the copy {}: {}", path_,
                                  have, copy, ec.message()));
  }
}

int Database::check_schema_version(int have, int known) const {
  if (have < 0 || have > known) {
    throw SqliteError(fmt::format("{}: schema version {} is not one this software knows (0..{}){}",
                                  path_, have, known,
                                  have > known ? ": newer software wrote it" : ""));
  }
  return have;
}

void Database::stamp_application_id() {
  auto app = prepare("PRAGMA application_id");
  app.step();
  if (app.column_int(0) != kStationApplicationId)
    exec(fmt::format("PRAGMA application_id = {}", kStationApplicationId));
}

Transaction::Transaction(Database& db) : db_(db) {
  db_.exec("BEGIN IMMEDIATE");
}

Transaction::~Transaction() {
  if (!done_) {
    try {
      db_.exec("ROLLBACK");
    } catch (...) {  // NOLINT(bugprone-empty-catch): nothing better to do in a destructor
    }
  }
}

void Transaction::commit() {
  try {
    db_.exec("COMMIT");
  } catch (...) {
    // A COMMIT that fails (disk full, I/O error, a file size limit) may already have rolled the
    // transaction back, or may leave it open (sqlite.org/lang_transaction.html, "Response To
    // Errors Within A Transaction": the application should ROLLBACK). Either way the connection
    // leaves here outside any transaction, so the next BEGIN starts clean.
    done_ = true;
    if (db_.in_transaction()) {
      try {
        db_.exec("ROLLBACK");
      } catch (...) {  // NOLINT(bugprone-empty-catch): the COMMIT's error is the one to report
      }
    }
    throw;
  }
  done_ = true;
}

}  // namespace station
