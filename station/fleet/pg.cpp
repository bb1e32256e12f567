// libpq calls, all non-blocking under a deadline (pg.hpp): PQconnectStartParams / PQconnectPoll,
// PQsendQuery / PQsendQueryParams with PQflush, PQconsumeInput, PQisBusy and PQgetResult
// (postgresql.org/docs/15/libpq-async.html), COPY via PQputCopyData / PQputCopyEnd
// (libpq-copy.html), PQcancel (libpq-cancel.html).
#include "station/fleet/pg.hpp"

#include <fmt/format.h>
#include <poll.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <future>
#include <thread>

namespace station::fleet {
namespace {

using Clock = std::chrono::steady_clock;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

std::string trimmed(const char* msg) {
  std::string s = msg != nullptr ? msg : "";
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

}  // namespace

std::optional<std::string> PgResult::opt_text(int row, int col) const {
  if (is_null(row, col)) return std::nullopt;
  return text(row, col);
}

double PgResult::number(int row, int col) const {
  return std::strtod(PQgetvalue(r_.get(), row, col), nullptr);
}

long long PgResult::integer(int row, int col) const {
  return std::strtoll(PQgetvalue(r_.get(), row, col), nullptr, 10);
}

long long PgResult::affected() const {
  return std::atoll(PQcmdTuples(r_.get()));
}

namespace {

/// The `options` keyword of `url` (command-line options for the server, e.g. -c search_path=x),
/// empty when it has none: ours are appended to it, never put in its place.
std::string url_options(const std::string& url) {
  std::string out;
  if (PQconninfoOption* opts = PQconninfoParse(url.c_str(), nullptr)) {
    for (auto* o = opts; o->keyword != nullptr; ++o)
      if (std::string_view(o->keyword) == "options" && o->val != nullptr) out = o->val;
    PQconninfoFree(opts);
  }
  return out;
}

}  // namespace

// Keywords before "dbname" are defaults the URL may override; the configured ones come after it
// and win (expand_dbname = 1: "later keywords override", libpq-connect.html, PQconnectdbParams).
// client_min_messages: a NOTICE ("stage table exists, skipping") is not for the operator.
// connect_timeout is ignored by PQconnectPoll (libpq-connect.html): the loop below keeps it.
PgConnection::PgConnection(const PgTarget& t, PgWatch watch)
    : call_timeout_s_(t.call_timeout_s()), watch_(std::move(watch)) {
  std::string options = url_options(t.url);
  options += fmt::format("{}-c statement_timeout={} -c client_min_messages=warning",
                         options.empty() ? "" : " ",
                         static_cast<long long>(std::ceil(t.statement_timeout_s * 1000)));
  const long long user_timeout_ms = std::llround(t.call_timeout_s() * 1000);
  std::vector<std::pair<std::string, std::string>> kv = {
      {"application_name", "gyro-station"},
      {"keepalives", "1"},
      {"keepalives_idle", "30"},
      {"keepalives_interval", "10"},
      {"keepalives_count", "3"},
      {"tcp_user_timeout", std::to_string(user_timeout_ms)},
      {"dbname", t.url}};
  kv.insert(kv.end(), t.keywords.begin(), t.keywords.end());
  kv.emplace_back("options", options);
  kv.emplace_back("client_encoding", "UTF8");
  std::vector<const char*> keys, values;
  for (const auto& [k, v] : kv) {
    keys.push_back(k.c_str());
    values.push_back(v.c_str());
  }
  keys.push_back(nullptr);
  values.push_back(nullptr);
  conn_.reset(PQconnectStartParams(keys.data(), values.data(), 1));
  if (!conn_) throw PgError("PostgreSQL: out of memory");
  connect(t);
}

// The PQconnectPoll loop (libpq-connect.html): start as if it had said "writing", then wait on
// the socket for what it asks, until OK or FAILED; the socket may change between calls (another
// host of a list), so it is read again each time.
void PgConnection::connect(const PgTarget& t) {
  const auto started = Clock::now();
  const auto deadline = started + seconds(t.connect_timeout_s);
  auto st = PQstatus(conn_.get()) == CONNECTION_BAD ? PGRES_POLLING_FAILED : PGRES_POLLING_WRITING;
  while (st != PGRES_POLLING_OK && st != PGRES_POLLING_FAILED) {
    set_where();
    wait_socket(st == PGRES_POLLING_WRITING, deadline, "connect", started);
    st = PQconnectPoll(conn_.get());
  }
  set_where();
  if (st == PGRES_POLLING_FAILED || PQstatus(conn_.get()) != CONNECTION_OK)
    throw PgError(fmt::format("PostgreSQL {}: {}", where_, trimmed(PQerrorMessage(conn_.get()))));
  if (PQsetnonblocking(conn_.get(), 1) != 0) lost("set non-blocking");
  cancel_.reset(PQgetCancel(conn_.get()), PgFreeCancel{});
}

void PgConnection::set_where() {
  const char* host = PQhost(conn_.get());
  const char* port = PQport(conn_.get());
  const char* db = PQdb(conn_.get());
  where_ = fmt::format("{}:{}/{}", host != nullptr ? host : "?", port != nullptr ? port : "?",
                       db != nullptr ? db : "?");
}

// PQcancel blocks until the postmaster has read the request and closed the connection; it runs
// on a thread of its own holding the PGcancel, so a postmaster that never answers costs a thread
// until the process ends, never the caller's deadline.
bool PgConnection::cancel() const {
  if (!cancel_) return false;
  auto done = std::make_shared<std::promise<void>>();
  auto answered = done->get_future();
  std::thread([c = cancel_, done] {
    char err[256];
    PQcancel(c.get(), err, sizeof err);
    done->set_value();
  }).detach();
  return answered.wait_for(seconds(kPgCancelTimeoutS)) == std::future_status::ready;
}

// Past the deadline (or stopping): cancel, close (PQfinish on a non-blocking connection does not
// wait to send its Terminate), and say what went unanswered. The server rolls back what was open.
void PgConnection::abandon(std::string_view what, bool stopping, double limit_s) {
  const bool can_cancel = conn_ && cancel_;  // none before the connection is made
  const bool cancelled = can_cancel && cancel();
  conn_.reset();
  const std::string call(what.substr(0, 60));
  if (stopping) throw PgTimeout(fmt::format("PostgreSQL {}: {} given up: stopping", where_, call));
  throw PgTimeout(fmt::format(
      "PostgreSQL {}: {}: timed out, no answer within {:.1f} s (server frozen, overloaded or cut "
      "off?); {}disconnected",
      where_, call, limit_s,
      !can_cancel ? ""
      : cancelled ? "cancelled, "
                  : "cancel unanswered, "));
}

void PgConnection::lost(std::string_view what) {
  const std::string msg = conn_ ? trimmed(PQerrorMessage(conn_.get())) : "connection closed";
  conn_.reset();
  throw PgError(fmt::format("PostgreSQL {}: {}: {}", where_, what.substr(0, 60), msg));
}

PGconn* PgConnection::live(std::string_view what) {
  if (!conn_) throw PgError(fmt::format("PostgreSQL {}: {}: connection closed", where_, what));
  return conn_.get();
}

PgConnection::Deadline PgConnection::call_deadline() const {
  return Clock::now() + seconds(call_timeout_s_);
}

void PgConnection::wait_socket(bool write, Deadline deadline, std::string_view what,
                               Deadline started) {
  for (double next_report_s = kPgSlowCallS;;) {
    if (watch_.stop && watch_.stop()) abandon(what, true, 0);
    const auto now = Clock::now();
    if (now >= deadline)
      abandon(what, false, std::chrono::duration<double>(deadline - started).count());
    const double waited_s = std::chrono::duration<double>(now - started).count();
    if (waited_s >= next_report_s && watch_.waiting) {
      watch_.waiting(waited_s, what);
      next_report_s = waited_s + 1;
    }
    const auto slice = std::min<Clock::duration>(deadline - now, seconds(kPgPollSliceS));
    pollfd p{PQsocket(conn_.get()), static_cast<short>(POLLIN | (write ? POLLOUT : 0)), 0};
    if (p.fd < 0) lost(what);
    const int ms = static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(slice).count());
    const int n = ::poll(&p, 1, ms);
    if (n > 0) return;
    if (n < 0 && errno != EINTR) lost(what);
  }
}

// PQflush until the output is sent; reading what the server sends meanwhile (it may wait for us
// to read before it reads, libpq-async.html, PQflush).
void PgConnection::flush(Deadline deadline, std::string_view what, Deadline started) {
  for (;;) {
    const int f = PQflush(live(what));
    if (f == 0) return;
    if (f < 0) lost(what);
    wait_socket(true, deadline, what, started);
    if (PQconsumeInput(conn_.get()) == 0) lost(what);
  }
}

PGresult* PgConnection::next_result(Deadline deadline, std::string_view what, Deadline started) {
  while (PQisBusy(live(what)) != 0) {
    wait_socket(false, deadline, what, started);
    if (PQconsumeInput(conn_.get()) == 0) lost(what);
  }
  return PQgetResult(conn_.get());
}

// Like PQexec: every result is read; the first error is the call's, else the last result (a COPY
// stops at its COPY_IN result: the data follows).
PgResult PgConnection::run(std::string_view what, const std::function<int(PGconn*)>& send) {
  const auto started = Clock::now();
  const auto deadline = call_deadline();
  if (send(live(what)) != 1) lost(what);
  flush(deadline, what, started);
  std::unique_ptr<PGresult, PgClear> kept, failed;
  while (PGresult* r = next_result(deadline, what, started)) {
    const auto status = PQresultStatus(r);
    if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK && status != PGRES_COPY_IN) {
      if (!failed)
        failed.reset(r);
      else
        PQclear(r);
    } else {
      kept.reset(r);
    }
    if (status == PGRES_COPY_IN) break;
  }
  return check(failed ? failed.release() : kept.release(), what);
}

PgResult PgConnection::check(PGresult* raw, std::string_view what) {
  PgResult r(raw);
  const auto status = raw != nullptr ? PQresultStatus(raw) : PGRES_FATAL_ERROR;
  if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK || status == PGRES_COPY_IN) return r;
  const char* msg = raw != nullptr ? PQresultErrorMessage(raw)
                    : conn_        ? PQerrorMessage(conn_.get())
                                   : "connection closed";
  throw PgError(fmt::format("PostgreSQL {}: {}: {}", where_, what.substr(0, 60), trimmed(msg)));
}

PgResult PgConnection::exec(std::string_view sql) {
  const std::string text(sql);
  return run(sql, [&text](PGconn* c) { return PQsendQuery(c, text.c_str()); });
}

PgResult PgConnection::exec(std::string_view sql,
                            const std::vector<std::optional<std::string>>& params) {
  const std::string text(sql);
  std::vector<const char*> values;
  for (const auto& p : params) values.push_back(p ? p->c_str() : nullptr);
  return run(sql, [&](PGconn* c) {
    return PQsendQueryParams(c, text.c_str(), static_cast<int>(values.size()), nullptr,
                             values.data(), nullptr, nullptr, 0);
  });
}

long long PgConnection::copy_in(std::string_view table_and_columns,
                                const std::function<bool(std::string&)>& fill) {
  return copy_in_as(fmt::format("COPY {} FROM STDIN", table_and_columns), fill);
}

long long PgConnection::copy_in_binary(std::string_view table_and_columns,
                                       const std::function<bool(std::string&)>& fill) {
  return copy_in_as(fmt::format("COPY {} FROM STDIN (FORMAT binary)", table_and_columns), fill);
}

// A piece at a time: PQputCopyData (it returns 0 while libpq's buffer is full on a non-blocking
// connection: wait until the socket takes more), then PQflush until the socket has it all, so
// the next piece is made while the server reads this one; then PQputCopyEnd and the COPY's own
// result, all under one deadline (libpq-copy.html, libpq-async.html).
long long PgConnection::copy_in_as(const std::string& sql,
                                   const std::function<bool(std::string&)>& fill) {
  exec(sql);
  const auto started = Clock::now();
  const auto deadline = call_deadline();
  std::string piece;
  piece.reserve(kPgCopyPieceBytes + kPgCopyPieceBytes / 4);
  for (bool more = true; more;) {
    piece.clear();
    try {
      more = fill(piece);
    } catch (const std::exception& e) {  // the rows could not be made: the COPY fails, no row
      end_copy(e.what(), deadline, sql, started);
      throw;
    }
    if (!piece.empty()) put_copy_piece(piece, deadline, sql, started);
  }
  return end_copy(nullptr, deadline, sql, started);
}

long long PgConnection::copy_in(std::string_view table_and_columns, std::string_view data) {
  return copy_in(table_and_columns, [data](std::string& piece) mutable {
    piece.assign(data.substr(0, kPgCopyPieceBytes));
    data.remove_prefix(piece.size());
    return !data.empty();
  });
}

void PgConnection::put_copy_piece(std::string_view piece, Deadline deadline, std::string_view what,
                                  Deadline started) {
  for (int put;
       (put = PQputCopyData(live(what), piece.data(), static_cast<int>(piece.size()))) != 1;) {
    if (put < 0) lost(what);
    wait_socket(true, deadline, what, started);
    if (PQconsumeInput(conn_.get()) == 0) lost(what);
  }
  flush(deadline, what, started);
}

// As above: what the server sent meanwhile (an error, a NOTICE) must be read, or the socket
// stays readable, poll returns at once and the loop spins until the deadline. After a CopyFail
// the COPY's error result is the one expected: it is read and dropped.
long long PgConnection::end_copy(const char* why, Deadline deadline, std::string_view what,
                                 Deadline started) {
  for (int put; (put = PQputCopyEnd(live(what), why)) != 1;) {
    if (put < 0) lost(what);
    wait_socket(true, deadline, what, started);
    if (PQconsumeInput(conn_.get()) == 0) lost(what);
  }
  flush(deadline, what, started);
  std::unique_ptr<PGresult, PgClear> result(next_result(deadline, what, started));
  // Drain: libpq returns NULL after the last result of the COPY.
  while (PGresult* extra = next_result(deadline, what, started)) PQclear(extra);
  const long long rows = result ? std::atoll(PQcmdTuples(result.get())) : 0;
  if (why == nullptr) check(result.release(), what);
  return rows;
}

void append_copy_field(std::string& out, const std::optional<std::string_view>& value) {
  if (!value) {
    out += "\\N";
    return;
  }
  for (char ch : *value) {
    switch (ch) {
      case '\\':
        out += "\\\\";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        out += ch;
    }
  }
}

PgTransaction::PgTransaction(PgConnection& c) : c_(c) {
  c_.exec("BEGIN");
}

PgTransaction::~PgTransaction() {
  if (done_) return;
  try {
    c_.exec("ROLLBACK");
  } catch (...) {  // a dead connection rolls back by itself
  }
}

void PgTransaction::commit() {
  c_.exec("COMMIT");
  done_ = true;
}

}  // namespace station::fleet
