// libpq calls: PQconnectdbParams, PQexec / PQexecParams, COPY via PQputCopyData / PQputCopyEnd /
// PQgetResult (postgresql.org/docs/15/libpq-copy.html).
#include "station/fleet/pg.hpp"

#include <fmt/format.h>

#include <cstdlib>

namespace station::fleet {
namespace {

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
PgConnection::PgConnection(const PgTarget& t) {
  const std::string timeout = std::to_string(t.connect_timeout_s);
  std::string options = url_options(t.url);
  options += fmt::format("{}-c statement_timeout={} -c client_min_messages=warning",
                         options.empty() ? "" : " ", t.statement_timeout_ms);
  std::vector<std::pair<std::string, std::string>> kv = {
      {"connect_timeout", timeout},
      {"application_name", "gyro-station"},
      {"keepalives", "1"},
      {"keepalives_idle", "30"},
      {"keepalives_interval", "10"},
      {"keepalives_count", "3"},
      {"tcp_user_timeout", std::to_string(t.connect_timeout_s * 3000)},
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
  conn_.reset(PQconnectdbParams(keys.data(), values.data(), 1));
  if (!conn_) throw PgError("PostgreSQL: out of memory");
  const char* host = PQhost(conn_.get());
  where_ =
      fmt::format("{}:{}/{}", host != nullptr ? host : "?", PQport(conn_.get()), PQdb(conn_.get()));
  if (PQstatus(conn_.get()) != CONNECTION_OK)
    throw PgError(fmt::format("PostgreSQL {}: {}", where_, trimmed(PQerrorMessage(conn_.get()))));
  cancel_.reset(PQgetCancel(conn_.get()));
}

void PgConnection::cancel() const {
  char err[256];
  if (cancel_) PQcancel(cancel_.get(), err, sizeof err);
}

PgResult PgConnection::check(PGresult* raw, std::string_view what) {
  PgResult r(raw);
  const auto status = raw != nullptr ? PQresultStatus(raw) : PGRES_FATAL_ERROR;
  if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK || status == PGRES_COPY_IN) return r;
  const char* msg = raw != nullptr ? PQresultErrorMessage(raw) : PQerrorMessage(conn_.get());
  throw PgError(fmt::format("PostgreSQL {}: {}: {}", where_, what.substr(0, 60), trimmed(msg)));
}

PgResult PgConnection::exec(std::string_view sql) {
  const std::string text(sql);
  return check(PQexec(conn_.get(), text.c_str()), sql);
}

PgResult PgConnection::exec(std::string_view sql,
                            const std::vector<std::optional<std::string>>& params) {
  const std::string text(sql);
  std::vector<const char*> values;
  for (const auto& p : params) values.push_back(p ? p->c_str() : nullptr);
  return check(PQexecParams(conn_.get(), text.c_str(), static_cast<int>(values.size()), nullptr,
                            values.data(), nullptr, nullptr, 0),
               sql);
}

long long PgConnection::copy_in(std::string_view table_and_columns, std::string_view data) {
  const std::string sql = fmt::format("COPY {} FROM STDIN", table_and_columns);
  check(PQexec(conn_.get(), sql.c_str()), sql);
  if (PQputCopyData(conn_.get(), data.data(), static_cast<int>(data.size())) != 1 ||
      PQputCopyEnd(conn_.get(), nullptr) != 1) {
    throw PgError(
        fmt::format("PostgreSQL {}: {}: {}", where_, sql, trimmed(PQerrorMessage(conn_.get()))));
  }
  PGresult* raw = PQgetResult(conn_.get());
  const long long rows = raw != nullptr ? std::atoll(PQcmdTuples(raw)) : 0;
  check(raw, sql);
  // Drain: libpq returns NULL after the last result of the COPY.
  while (PGresult* extra = PQgetResult(conn_.get())) PQclear(extra);
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
