// RAII over libpq (PostgreSQL's C client, Debian libpq-dev): a move-only connection, results
// freed in their destructor, COPY FROM STDIN for bulk rows. Every call is bounded on the client
// (issue 34 point 5): the connection is non-blocking (PQconnectStartParams / PQconnectPoll,
// PQsendQuery / PQsendQueryParams, PQputCopyData / PQflush, PQconsumeInput / PQisBusy /
// PQgetResult, each wait a poll() on PQsocket; postgresql.org/docs/15/libpq-async.html and
// libpq-connect.html), so a server that stops answering with its TCP connection still up (a frozen
// backend, a half-dead link) cannot hold the caller: past the call's deadline the statement is
// cancelled (PQcancel, itself bounded), the connection closed and PgTimeout thrown; a stop asked
// for by the caller (a stopping service) ends the wait the same way at once. The server bounds
// its own side with statement_timeout (libpq "Parameter Key Words": options), keepalives and
// tcp_user_timeout. Failures throw PgError with the server's or libpq's message; the forwarder
// turns them into a backlog and a retry, never into a dead daemon.
#pragma once

#include <libpq-fe.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <functional>
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
/// A call past its deadline, or given up because the caller stops: cancelled and disconnected.
/// Whether a COMMIT in flight took effect is unknown; the resend's idempotent merge settles it.
class PgTimeout : public PgError {
 public:
  using PgError::PgError;
};

// The client's deadlines (issue 34 point 5). A healthy server answers a forwarder's statement in
// well under a second (a 50 000-row COPY and its merge: a few seconds); the server itself ends a
// statement after statement_timeout_s (60 s, the figure of issue 24) with its own error, which is
// the better message, so the client waits kPgServerGraceS beyond it before it decides the server
// is not working at all. A connection (TCP, TLS, startup, authentication) gets connect_timeout_s
// (10 s, as before). A cancel request is one short connection to the postmaster, answered at once
// by a working one: kPgCancelTimeoutS bounds it when the postmaster is itself gone or frozen.
inline constexpr double kPgConnectTimeoutS = 10;
inline constexpr double kPgStatementTimeoutS = 60;
inline constexpr double kPgServerGraceS = 10;
inline constexpr double kPgCancelTimeoutS = 5;
/// How often a wait looks at the caller's stop and how soon a slow call is first reported.
inline constexpr double kPgPollSliceS = 0.1;
inline constexpr double kPgSlowCallS = 2;
/// What a COPY hands libpq at a time (PQputCopyData): a few socket buffers' worth.
inline constexpr std::size_t kPgCopyPieceBytes = 64 * 1024;

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
  double connect_timeout_s = kPgConnectTimeoutS;
  double statement_timeout_s = kPgStatementTimeoutS;  ///< the server's; [fleet] timeout_s
  /// The client's deadline for one call: the server's timeout and its grace (at most as long
  /// again as the timeout itself, so a short timeout keeps a short deadline).
  double call_timeout_s() const {
    return statement_timeout_s + std::min(kPgServerGraceS, statement_timeout_s);
  }
};

/// What a connection's waits look at: `stop` true gives up now (PgTimeout); `waiting` hears of
/// a call still unanswered after kPgSlowCallS, then about once a second (seconds waited, the
/// call), from the waiting thread.
struct PgWatch {
  std::function<bool()> stop;
  std::function<void(double waited_s, std::string_view what)> waiting;
};

class PgConnection {
 public:
  /// Connects (bounded by connect_timeout_s); throws PgError naming the server.
  explicit PgConnection(const PgTarget& target, PgWatch watch = {});
  /// Runs `sql` (one or more statements, no parameters).
  PgResult exec(std::string_view sql);
  /// Runs one statement with text parameters ($1, $2, ...; nullopt is NULL).
  PgResult exec(std::string_view sql, const std::vector<std::optional<std::string>>& params);
  /// COPY `table_and_columns` FROM STDIN (text format); `data` is the rows already encoded
  /// (copy_field / '\t' / '\n'). Returns the number of rows the server took.
  long long copy_in(std::string_view table_and_columns, std::string_view data);
  /// The same, the rows made while they are sent: `fill` appends the next rows to its (emptied)
  /// buffer, about kPgCopyPieceBytes at a time, and returns false once none are left. Each piece
  /// goes to the socket before the next is made, so the caller reads and encodes at the server's
  /// pace, holding one piece.
  long long copy_in(std::string_view table_and_columns,
                    const std::function<bool(std::string&)>& fill);
  /// The same in COPY's binary format: `fill` writes the header, the tuples and the trailer
  /// (station/fleet/copy_binary.hpp).
  long long copy_in_binary(std::string_view table_and_columns,
                           const std::function<bool(std::string&)>& fill);
  /// Asks the server to cancel the statement in flight (PQcancel with the PGcancel made at
  /// connect, libpq-cancel.html), waiting at most kPgCancelTimeoutS. False: no answer.
  bool cancel() const;
  /// False once the connection is lost or given up (a failure then is the link's, not the data's).
  bool ok() const { return conn_ && PQstatus(conn_.get()) == CONNECTION_OK; }
  /// Where it is connected ("host:port/db"), for messages.
  const std::string& where() const { return where_; }

 private:
  using Deadline = std::chrono::steady_clock::time_point;
  PgResult check(PGresult* r, std::string_view what);
  void connect(const PgTarget& t);
  void set_where();
  Deadline call_deadline() const;
  /// Waits until the socket is readable (or writable too, `write`), the deadline or a stop.
  void wait_socket(bool write, Deadline deadline, std::string_view what, Deadline started);
  void flush(Deadline deadline, std::string_view what, Deadline started);
  /// The next result of the call in flight (nullptr: the call is done).
  PGresult* next_result(Deadline deadline, std::string_view what, Deadline started);
  /// Hands libpq one piece of a COPY's data and sends it (waiting while the socket is full).
  void put_copy_piece(std::string_view piece, Deadline deadline, std::string_view what,
                      Deadline started);
  long long copy_in_as(const std::string& sql, const std::function<bool(std::string&)>& fill);
  /// Ends a COPY (CopyFail with `why` when `why` is given) and reads its result.
  long long end_copy(const char* why, Deadline deadline, std::string_view what, Deadline started);
  /// Sends with `send` (PQsendQuery...), then reads every result: the first error, else the last.
  PgResult run(std::string_view what, const std::function<int(PGconn*)>& send);
  [[noreturn]] void abandon(std::string_view what, bool stopping, double limit_s);
  [[noreturn]] void lost(std::string_view what);
  PGconn* live(std::string_view what);
  std::unique_ptr<PGconn, PgFinish> conn_;
  std::shared_ptr<PGcancel> cancel_;  ///< shared with a cancel that outlives its wait
  std::string where_;
  double call_timeout_s_ = 0;
  PgWatch watch_;
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
