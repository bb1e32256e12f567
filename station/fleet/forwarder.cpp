#include "station/fleet/forwarder.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "station/fleet/fleet_merge.hpp"
#include "station/fleet/fleet_schema.hpp"
#include "station/store/store.hpp"

namespace station::fleet {
namespace {

// No sample time is below this (t_s counts from a run's start).
constexpr double kBeforeAnySample = -1e300;

/// One read transaction: every SELECT of an item sees one snapshot of the file (WAL readers do
/// not block the daemon's writes; sqlite.org/wal.html "Concurrency").
class ReadSnapshot {
 public:
  explicit ReadSnapshot(Database& db) : db_(db) { db_.exec("BEGIN"); }
  ~ReadSnapshot() {
    try {
      db_.exec("COMMIT");
    } catch (...) {  // a read transaction has nothing to lose
    }
  }
  ReadSnapshot(const ReadSnapshot&) = delete;
  ReadSnapshot& operator=(const ReadSnapshot&) = delete;

 private:
  Database& db_;
};

void bind_named(Statement& st, const char* name, std::int64_t v) {
  if (int i = st.parameter_index(name); i > 0) st.bind(i, v);
}
void bind_named(Statement& st, const char* name, double v) {
  if (int i = st.parameter_index(name); i > 0) st.bind(i, v);
}
void bind_named(Statement& st, const char* name, std::string_view v) {
  if (int i = st.parameter_index(name); i > 0) st.bind(i, v);
}

/// An item the server will not take now: refused (retried after a back-off) or held (the server
/// has a newer state of it; never written over).
struct ItemRefused : std::runtime_error {
  ItemRefused(const std::string& what, bool held) : std::runtime_error(what), hold(held) {}
  bool hold;
};

ItemRefused held(Item item, std::int64_t local_id, const std::string& what) {
  return ItemRefused(fmt::format("{} {}: {} (this file restored from a backup, or the server's "
                                 "row edited?); held, nothing of it written (`station sync "
                                 "--retry-held` checks again)",
                                 item_name(item), local_id, what),
                     true);
}

/// The central table whose row is the item itself (its key is the item's uuid).
const FleetTable& item_table(Item item) {
  for (const auto& t : fleet_tables())
    if (t.item == item && t.key == "uuid") return t;
  throw std::logic_error("no item table");
}

std::int64_t item_order(std::string_view item) {
  for (Item i : {Item::run, Item::fit, Item::release, Item::verification})
    if (item_name(i) == item) return static_cast<std::int64_t>(i);
  return -1;
}

}  // namespace

PassResult& PassResult::operator+=(const PassResult& o) {
  items += o.items;
  rows += o.rows;
  appended += o.appended;
  failed += o.failed;
  more = o.more;
  if (!o.last_error.empty()) last_error = o.last_error;
  return *this;
}

Forwarder::Forwarder(std::string db_path, PgTarget target, ForwardOptions options)
    : db_path_(std::move(db_path)), target_(std::move(target)), options_(std::move(options)) {}

double unix_now_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

double next_backoff_s(double previous_s) {
  return previous_s <= 0 ? 0.5 : std::min(60.0, previous_s * 2);
}

void Forwarder::open() {
  if (!read_) read_.emplace(db_path_, OpenMode::read_only);
  if (!write_) write_.emplace(db_path_, OpenMode::existing);
  if (identity_.empty()) {
    auto id = read_->prepare("SELECT uuid FROM station_identity");
    if (!id.step()) throw SqliteError(db_path_ + ": no station identity (migration 10)");
    identity_ = id.column_text(0);
  }
  if (!pg_) pg_.emplace(target_, watch_);
  // Every pass: a server migrated meanwhile is seen (a cheap query).
  require_fleet_schema(*pg_);
}

void Forwarder::disconnect() {
  pg_.reset();
}

void Forwarder::release_held() {
  if (!write_) write_.emplace(db_path_, OpenMode::existing);
  write_->exec(
      "UPDATE fleet_outbox SET held_reason = NULL, retry_after_unix = NULL, refusals = 0 WHERE "
      "held_reason IS NOT NULL");
}

PassResult Forwarder::pass(std::int64_t max_items, const std::function<bool()>& stop) {
  open();
  std::vector<std::pair<Item, std::int64_t>> pending;
  {
    auto st = read_->prepare(
        "SELECT item, local_id FROM fleet_outbox WHERE held_reason IS NULL AND "
        "coalesce(retry_after_unix, 0) <= ?1 AND (acked < changes OR (?2 AND item = 'run' AND "
        "samples_done = 0)) ORDER BY CASE item WHEN 'run' THEN 0 WHEN 'fit' THEN 1 WHEN "
        "'release' THEN 2 ELSE 3 END, local_id LIMIT ?3");
    st.bind(1, unix_now_s()).bind(2, options_.samples ? 1 : 0).bind(3, max_items);
    while (st.step())
      pending.emplace_back(static_cast<Item>(item_order(st.column_text(0))), st.column_int(1));
  }
  PassResult r;
  r.more = static_cast<std::int64_t>(pending.size()) == max_items;
  for (const auto& [item, id] : pending) {
    if (stop && stop()) {
      r.more = true;
      break;
    }
    try {
      const Sent sent = send_item(item, id);
      r.rows += sent.rows;
      r.appended += sent.appended;
      if (sent.complete) ++r.items;
      r.more = r.more || !sent.complete;
    } catch (const ItemRefused& e) {
      ++r.failed;
      r.last_error = e.what();
      record_error(item, id, e.what(), e.hold);
    } catch (const PgError& e) {
      if (!pg_->ok()) {  // the link, not the data: nothing more this pass
        disconnect();
        throw;
      }
      ++r.failed;
      r.last_error = e.what();
      record_error(item, id, e.what(), false);
    }
  }
  return r;
}

Forwarder::Sent Forwarder::send_item(Item item, std::int64_t local_id) {
  ReadSnapshot snap(*read_);
  auto ch = read_->prepare("SELECT changes FROM fleet_outbox WHERE item = ? AND local_id = ?");
  ch.bind(1, item_name(item)).bind(2, local_id);
  const std::int64_t changes = ch.step() ? ch.column_int(0) : 0;
  Sent sent;
  PgTransaction tx(*pg_);
  const std::string uuid = send_item_row(item, local_id, sent);
  if (item == Item::run) send_run(local_id, uuid, sent);
  tx.commit();
  acknowledge(item, local_id, changes, sent);
  return sent;
}

// The item's own row: it must be readable with what it refers to (a release whose fit is gone
// would otherwise be acknowledged unsent), and the server must not hold a newer or a different
// state of it (a file restored from a backup is held, nothing of it written).
std::string Forwarder::send_item_row(Item item, std::int64_t local_id, Sent& sent) {
  const auto& t = item_table(item);
  auto st = read_->prepare(t.select);
  bind_named(st, ":id", local_id);
  bind_named(st, ":station", std::string_view(options_.station));
  const auto rows = encode_rows(st);
  if (rows.rows != 1)
    throw ItemRefused(fmt::format("{} {}: not readable with what it refers to (its run or fit is "
                                  "gone from the file)",
                                  item_name(item), local_id),
                      false);
  stage_rows(*pg_, t, rows);
  if (const auto taken = station_name_taken(*pg_, t, identity_))
    throw ItemRefused(fmt::format("{} {}: {}", item_name(item), local_id, *taken), false);
  if (const auto diverged = first_diverged(*pg_, t)) throw held(item, local_id, *diverged);
  sent.rows += merge_staged(*pg_, t, {});
  auto u = read_->prepare(fmt::format("SELECT uuid FROM {} WHERE id = ?", t.name));
  u.bind(1, local_id);
  u.step();
  return u.column_text(0);
}

void Forwarder::send_run(std::int64_t run_id, const std::string& uuid, Sent& sent) {
  std::int64_t budget = options_.batch_rows;
  for (const auto& t : fleet_tables()) {
    if (t.item != Item::run || t.merge != Merge::replace_set) continue;
    auto st = read_->prepare(t.select);
    bind_named(st, ":id", run_id);
    sent.rows += stage_and_merge(*pg_, t, encode_rows(st), uuid);
  }
  append_events(run_id, uuid, sent, budget);
  if (options_.samples) append_samples(run_id, uuid, sent, budget);
}

// Appended rows resume at the server's high-water mark, and restate the row at the mark: the
// file must hold it, with the same content, or the two have parted (held); that row alone is
// staged and compared. The rows after it cannot be on the server (the mark is its highest, read
// in this transaction, and one process at a time forwards a file: the writer's lock), so they go
// straight into the central table by one COPY, read from SQLite as the server takes them: no
// staging table, no merge (issue 37: INSERT ... ON CONFLICT from a staged copy was 2.4 s and
// the divergence join over the whole batch 0.4 s of a 13 h run's 4.2 s). Two copies of one file
// forwarding at once would meet a duplicate key: the item is refused, retried, and compared.
void Forwarder::append_from(const FleetTable& t, Statement& st, std::optional<double> mark,
                            int mark_col, Sent& sent, std::int64_t& budget, std::int64_t run_id,
                            std::optional<double>& reached, std::span<const PgType> binary) {
  bool row = st.step();
  if (mark) {
    if (!row || st.column_double(mark_col) != *mark)
      throw held(Item::run, run_id,
                 fmt::format("the server holds {} this file does not have", t.name));
    EncodedRows at{{}, 1, mark, mark};
    append_copy_row(st, at.data);
    stage_rows(*pg_, t, at);
    if (const auto diverged = first_diverged(*pg_, t)) throw held(Item::run, run_id, *diverged);
    row = st.step();
  }
  std::int64_t fresh = 0;
  reached = mark;
  if (row) {
    const auto copy = fmt::format("{} ({})", t.name, t.columns);
    const auto names = split_columns(t.columns);
    bool first = true;
    const auto fill = [&](std::string& piece) {
      if (first && !binary.empty()) append_binary_copy_header(piece);
      first = false;
      for (; row && piece.size() < kPgCopyPieceBytes; row = st.step()) {
        if (binary.empty())
          append_copy_row(st, piece);
        else
          append_binary_copy_row(st, binary, names, piece);
        reached = st.column_double(mark_col);
        ++fresh;
      }
      if (!row && !binary.empty()) append_binary_copy_trailer(piece);
      return row;
    };
    try {
      sent.rows += binary.empty() ? pg_->copy_in(copy, fill) : pg_->copy_in_binary(copy, fill);
    } catch (const CopyValueError& e) {  // as the server refuses a text value it cannot read
      throw ItemRefused(fmt::format("run {}: {}: {}", run_id, t.name, e.what()), false);
    }
  }
  sent.appended += fresh;
  budget -= fresh;
  if (budget <= 0) sent.complete = false;
}

void Forwarder::append_events(std::int64_t run_id, const std::string& run_uuid, Sent& sent,
                              std::int64_t& budget) {
  const auto& t = fleet_table("events");
  auto have = pg_->exec("SELECT max(local_id) FROM events WHERE run_uuid = $1", {run_uuid});
  const std::optional<double> mark =
      have.is_null(0, 0) ? std::nullopt : std::optional<double>(have.number(0, 0));
  auto st = read_->prepare(t.select);
  bind_named(st, ":id", run_id);
  bind_named(st, ":after", static_cast<std::int64_t>(mark.value_or(1)) - 1);  // from the mark
  bind_named(st, ":limit", budget + 1);
  std::optional<double> reached;
  append_from(t, st, mark, 1, sent, budget, run_id, reached);
  if (reached) sent.events_after = static_cast<std::int64_t>(*reached);
}

void Forwarder::append_samples(std::int64_t run_id, const std::string& run_uuid, Sent& sent,
                               std::int64_t& budget) {
  const auto& t = fleet_table("samples");
  auto serials = read_->prepare("SELECT serial FROM run_slots WHERE run_id = ? ORDER BY slot");
  serials.bind(1, run_id);
  std::optional<double> lowest;
  while (serials.step()) {
    const std::string serial = serials.column_text(0);
    auto have = pg_->exec("SELECT max(t_s) FROM samples WHERE run_uuid = $1 AND serial = $2",
                          {run_uuid, serial});
    const std::optional<double> mark =
        have.is_null(0, 0) ? std::nullopt : std::optional<double>(have.number(0, 0));
    std::optional<double> reached = mark;
    if (budget > 0) {
      auto st = read_->prepare(t.select);
      bind_named(st, ":id", run_id);
      bind_named(st, ":serial", std::string_view(serial));
      // t_s > the double just below the mark: from the mark itself.
      bind_named(st, ":after", mark ? std::nextafter(*mark, -HUGE_VAL) : kBeforeAnySample);
      bind_named(st, ":limit", budget + 1);
      append_from(t, st, mark, 2, sent, budget, run_id, reached, kCentralSampleTypes);
    } else {
      sent.complete = false;
    }
    const double at = reached.value_or(kBeforeAnySample);
    lowest = lowest ? std::min(*lowest, at) : at;
  }
  sent.samples_after = lowest;
}

void Forwarder::acknowledge(Item item, std::int64_t local_id, std::int64_t changes,
                            const Sent& sent) {
  auto st = write_->prepare(
      "UPDATE fleet_outbox SET acked = CASE WHEN ?1 THEN max(acked, ?2) ELSE acked END, "
      "samples_done = CASE WHEN ?1 AND ?8 AND changes = ?2 THEN 1 ELSE samples_done END, "
      "acked_utc = ?3, events_acked_id = coalesce(?4, events_acked_id), "
      "samples_acked_t_s = coalesce(?5, samples_acked_t_s), last_error = NULL, refusals = 0, "
      "retry_after_unix = NULL WHERE item = ?6 AND local_id = ?7");
  st.bind(1, sent.complete ? 1 : 0).bind(2, changes).bind(3, utc_now_iso());
  if (sent.events_after)
    st.bind(4, *sent.events_after);
  else
    st.bind_null(4);
  st.bind(5, sent.samples_after);
  st.bind(6, item_name(item)).bind(7, local_id).bind(8, options_.samples ? 1 : 0);
  st.step();
}

// A refused item waits before its next attempt as a failing link does (next_backoff_s, once per
// refusal in a row), so one the server keeps refusing neither spins nor blocks the items behind
// it; a held one waits for a person.
void Forwarder::record_error(Item item, std::int64_t local_id, const std::string& error,
                             bool hold) {
  auto n = write_->prepare("SELECT refusals FROM fleet_outbox WHERE item = ? AND local_id = ?");
  n.bind(1, item_name(item)).bind(2, local_id);
  double wait_s = 0;
  for (std::int64_t k = n.step() ? n.column_int(0) : 0; k >= 0 && wait_s < 60; --k)
    wait_s = next_backoff_s(wait_s);
  auto st = write_->prepare(
      "UPDATE fleet_outbox SET last_error = ?1, refusals = refusals + 1, retry_after_unix = ?2, "
      "held_reason = CASE WHEN ?3 THEN ?1 END WHERE item = ?4 AND local_id = ?5");
  st.bind(1, error).bind(2, unix_now_s() + wait_s).bind(3, hold ? 1 : 0);
  st.bind(4, item_name(item)).bind(5, local_id);
  st.step();
}

// Rows behind the pending runs, by index ranges only: events by id, samples per serial by t_s
// (the samples' key is run, serial, t_s) — no scan of what was sent.
Backlog Forwarder::backlog() {
  if (!count_) count_.emplace(db_path_, OpenMode::read_only);
  ReadSnapshot snap(*count_);
  Backlog b;
  auto n = count_->prepare(
      "SELECT count(*) FILTER (WHERE item = 'run' AND held_reason IS NULL), "
      "count(*) FILTER (WHERE held_reason IS NULL), count(*) FILTER (WHERE held_reason IS NOT "
      "NULL) FROM fleet_outbox WHERE acked < changes OR (?1 AND item = 'run' AND samples_done = "
      "0)");
  n.bind(1, options_.samples ? 1 : 0);
  n.step();
  b.runs = n.column_int(0);
  b.items = n.column_int(1);
  b.held = n.column_int(2);
  auto rows = count_->prepare(
      "SELECT coalesce(sum((SELECT count(*) FROM events AS e WHERE e.run_id = o.local_id AND "
      "e.id > coalesce(o.events_acked_id, 0)) + CASE WHEN ?1 THEN (SELECT count(*) FROM "
      "run_slots AS rs JOIN samples AS s ON s.run_id = rs.run_id AND s.serial = rs.serial AND "
      "s.t_s > coalesce(o.samples_acked_t_s, -1e300) WHERE rs.run_id = o.local_id) ELSE 0 END), "
      "0) FROM fleet_outbox AS o WHERE o.item = 'run' AND o.held_reason IS NULL AND (o.acked < "
      "o.changes OR (?1 AND o.samples_done = 0))");
  rows.bind(1, options_.samples ? 1 : 0);
  rows.step();
  b.rows = b.items + rows.column_int(0);
  return b;
}

}  // namespace station::fleet
