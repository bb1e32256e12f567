// RAII over the SQLite C API (SQLiteCpp's shape): a move-only database, prepared statements,
// and a transaction that rolls back in its destructor unless committed. Errors throw
// SqliteError naming the database and the statement: storage failures are setup-class faults.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "station/common/database_lock.hpp"
#include "station/store/database_access.hpp"

namespace station {

/// A SQLite failure: database path, statement and sqlite3_errmsg.
class SqliteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SqliteClose {
  void operator()(sqlite3* db) const noexcept { sqlite3_close_v2(db); }
};
struct SqliteFinalize {
  void operator()(sqlite3_stmt* s) const noexcept { sqlite3_finalize(s); }
};

/// One prepared statement. bind() is 1-based; step() returns true while rows come.
class Statement {
 public:
  Statement(sqlite3* db, std::string_view sql, std::string db_path);
  Statement& bind(int i, double v);
  Statement& bind(int i, std::int64_t v);
  Statement& bind(int i, int v) { return bind(i, static_cast<std::int64_t>(v)); }
  Statement& bind(int i, std::string_view v);
  Statement& bind(int i, std::optional<double> v);
  Statement& bind_null(int i);
  /// Runs one step; true when a row is available.
  bool step();
  /// Resets for re-use with new bindings.
  void reset();
  double column_double(int c) const { return sqlite3_column_double(stmt_.get(), c); }
  std::int64_t column_int(int c) const { return sqlite3_column_int64(stmt_.get(), c); }
  std::string column_text(int c) const;
  bool column_is_null(int c) const { return sqlite3_column_type(stmt_.get(), c) == SQLITE_NULL; }
  /// SQLITE_INTEGER, SQLITE_FLOAT, SQLITE_TEXT, SQLITE_BLOB or SQLITE_NULL.
  int column_type(int c) const { return sqlite3_column_type(stmt_.get(), c); }
  int column_count() const { return sqlite3_column_count(stmt_.get()); }
  /// Index of a named parameter (":name"), 0 when the statement has none by that name.
  int parameter_index(const char* name) const {
    return sqlite3_bind_parameter_index(stmt_.get(), name);
  }

 private:
  [[noreturn]] void fail(const char* what) const;
  std::unique_ptr<sqlite3_stmt, SqliteFinalize> stmt_;
  sqlite3* db_;
  std::string db_path_;
};

/// A statement borrowed from a cache (Store::cached): reset, bindings cleared, when the lease ends,
/// so a half-read result never holds the database's read snapshot.
class StatementLease {
 public:
  explicit StatementLease(Statement& s) : s_(&s) {}
  ~StatementLease() { s_->reset(); }
  StatementLease(const StatementLease&) = delete;
  StatementLease& operator=(const StatementLease&) = delete;
  Statement* operator->() const { return s_; }
  Statement& operator*() const { return *s_; }

 private:
  Statement* s_;
};

/// How a command may touch its database file.
enum class OpenMode {
  create,     ///< the daemon: create the file when missing, migrate it
  existing,   ///< writers that must not create (fit): the file must exist and be a station DB
  read_only,  ///< readers (export, replay, report): SQLITE_OPEN_READONLY, never written
};

/// A database file. Locked before SQLite opens it (a writer exclusively, a reader shared:
/// database_access.hpp); checked with PRAGMA quick_check before anything else touches it; opened
/// in WAL mode with a busy timeout when writable; applies migrations on request.
/// PRAGMA application_id of a station database ("GTCL", gyro thermal calibration): a file's
/// header says whose it is (sqlite.org/fileformat2.html, "Application ID"). Files written before
/// it was set are recognised by their schema version and tables, and get it at the next write.
inline constexpr std::int32_t kStationApplicationId = 0x4754434C;

class Database {
 public:
  /// Opens `path` as `mode` allows; throws SqliteError naming the path (missing, not a
  /// database, corrupt), InputError when another process writes it and `mode` writes, or when it
  /// is reached by another name than its write-ahead log's.
  explicit Database(const std::string& path, OpenMode mode = OpenMode::create);
  /// Runs one or more statements without results.
  void exec(std::string_view sql);
  /// Prepares a statement.
  Statement prepare(std::string_view sql) { return Statement(db_.get(), sql, path_); }
  /// Row id of the last insert.
  std::int64_t last_insert_id() const { return sqlite3_last_insert_rowid(db_.get()); }
  /// Applies schemas/migrations/*.sql past PRAGMA user_version in one transaction, after a
  /// copy of the file as it was (`PATH.schema-vN.STAMP.bak`). Throws when the file is newer than
  /// this software, or when the copy cannot be written.
  void migrate();
  /// PRAGMA user_version.
  int schema_version();
  const std::string& path() const { return path_; }
  OpenMode mode() const { return mode_; }
  /// A reader that opened the file with `immutable=1` (no lock: database_access.hpp) and whose
  /// file changed since: throws InputError "PATH: the database changed while it was read: retry".
  /// Called after a command's reads, before it writes its output. Nothing for other opens.
  void check_unchanged() const;
  /// True inside BEGIN ... COMMIT (sqlite3_get_autocommit is 0).
  bool in_transaction() const { return sqlite3_get_autocommit(db_.get()) == 0; }

 private:
  /// PRAGMA quick_check: throws SqliteError with the first problem it reports.
  void quick_check();
  /// Whether the file is empty (true: no schema, a new database) or a station database (false);
  /// throws SqliteError for anyone else's file. Reads only: decided before any PRAGMA writes.
  bool identify_empty();
  /// Sets the application_id on a station file written before it existed.
  void stamp_application_id();
  /// `have` when it is a version this software can migrate from; throws otherwise (a negative
  /// or future user_version must never index the migration table).
  int check_schema_version(int have, int known) const;
  /// VACUUM INTO `path.schema-vHAVE.STAMP.bak` (via a .tmp and a rename) before migrating.
  void backup_before_migrating(int have);
  /// This process's lock on the file (database_access.hpp), released after the connection closes.
  std::optional<DatabaseHold> hold_;
  /// An immutable reader's stamp of the file before its first read (database_access.hpp).
  std::optional<FileStamp> stamp_;
  std::unique_ptr<sqlite3, SqliteClose> db_;
  std::string path_;
  OpenMode mode_;
};

/// BEGIN IMMEDIATE now; ROLLBACK in the destructor unless commit() ran.
class Transaction {
 public:
  explicit Transaction(Database& db);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  Database& db_;
  bool done_ = false;
};

}  // namespace station
