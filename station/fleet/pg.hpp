// RAII over libpq (PostgreSQL's C client, Debian libpq-dev): a move-only connection, results
// freed in their destructor, COPY FROM STDIN for bulk rows. Every I/O is bounded: the connection
// is opened with connect_timeout, tcp_user_timeout and keepalives, and every statement runs under
// statement_timeout (libpq "Parameter Key Words", postgresql.org/docs/15/libpq-connect.html).
// Failures throw PgError with the server's or libpq's message; the forwarder turns them into a
// backlog and a retry, never into a dead daemon.
#pragma once

#include <libpq-fe.h>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace station::fleet {

class PgError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct PgFinish {
  void operator()(PGconn* c) const noexcept { PQfinish(c); }
};
struct PgClear {
  void operator()(PGresult* r) const noexcept { PQclear(r); }
};
struct PgFreeCancel {
  void operator()(PGcancel* c) const noexcept { PQfreeCancel(c); }
};

/// One query's rows (text format). Move-only through its unique_ptr.
class PgResult {
 public:
  explicit PgResult(PGresult* r) : r_(r) {}
  int rows() const { return PQntuples(r_.get()); }
  int columns() const { return PQnfields(r_.get()); }
  bool is_null(int row, int col) const { return PQgetisnull(r_.get(), row, col) != 0; }
  std::string text(int row, int col) const { return PQgetvalue(r_.get(), row, col); }
  std::optional<std::string> opt_text(int row, int col) const;
  double number(int row, int col) const;
  long long integer(int row, int col) const;
  std::string column_name(int col) const { return PQfname(r_.get(), col); }
  /// Rows an INSERT, UPDATE or DELETE touched (PQcmdTuples).
  long long affected() const;

 private:
  std::unique_ptr<PGresult, PgClear> r_;
};

/// Where and how to connect: a libpq connection URI or key=value string (no password in it;
/// libpq reads PGPASSWORD, PGPASSFILE or `passfile`), plus TLS and other keywords passed through
/// as libpq names them (sslmode, sslrootcert, sslcert, sslkey, passfile, ...).
struct PgTarget {
  std::string url;
  std::vector<std::pair<std::string, std::string>> keywords;
  int connect_timeout_s = 10;
  int statement_timeout_ms = 60'000;
};

class PgConnection {
 public:
  /// Connects (bounded by connect_timeout); throws PgError naming the server.
  explicit PgConnection(const PgTarget& target);
  /// Runs `sql` (one or more statements, no parameters).
  PgResult exec(std::string_view sql);
  /// Runs one statement with text parameters ($1, $2, ...; nullopt is NULL).
  PgResult exec(std::string_view sql, const std::vector<std::optional<std::string>>& params);
  /// COPY `table_and_columns` FROM STDIN (text format); `data` is the rows already encoded
  /// (copy_field / '\t' / '\n'). Returns the number of rows the server took.
  long long copy_in(std::string_view table_and_columns, std::string_view data);
  /// Asks the server to cancel the statement in flight; callable from another thread while this
  /// one waits (PQcancel with the PGcancel made at connect, libpq-cancel.html).
  void cancel() const;
  /// False once the connection is lost (a failure then is the link's, not the data's).
  bool ok() const { return PQstatus(conn_.get()) == CONNECTION_OK; }
  /// Where it is connected ("host:port/db"), for messages.
  const std::string& where() const { return where_; }

 private:
  PgResult check(PGresult* r, std::string_view what);
  std::unique_ptr<PGconn, PgFinish> conn_;
  std::unique_ptr<PGcancel, PgFreeCancel> cancel_;
  std::string where_;
};

/// One field of a COPY text-format row: `\N` for NULL, else the value with backslash, tab,
/// newline and carriage return escaped (postgresql.org/docs/15/sql-copy.html, "Text Format").
void append_copy_field(std::string& out, const std::optional<std::string_view>& value);

/// BEGIN now; ROLLBACK in the destructor unless commit() ran.
class PgTransaction {
 public:
  explicit PgTransaction(PgConnection& c);
  ~PgTransaction();
  PgTransaction(const PgTransaction&) = delete;
  PgTransaction& operator=(const PgTransaction&) = delete;
  void commit();

 private:
  PgConnection& c_;
  bool done_ = false;
};

}  // namespace station::fleet
