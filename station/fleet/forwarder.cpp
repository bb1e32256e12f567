#include "station/fleet/forwarder.hpp"

#include <fmt/format.h>

#include <ctime>

#include "station/fleet/fleet_merge.hpp"
#include "station/fleet/fleet_schema.hpp"

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

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buf;
}

std::int64_t item_order(std::string_view item) {
  for (Item i : {Item::run, Item::fit, Item::release, Item::verification})
    if (item_name(i) == item) return static_cast<std::int64_t>(i);
  return -1;
}

}  // namespace

Forwarder::Forwarder(std::string db_path, PgTarget target, ForwardOptions options)
    : db_path_(std::move(db_path)), target_(std::move(target)), options_(std::move(options)) {}

void Forwarder::open() {
  if (!read_) read_.emplace(db_path_, OpenMode::read_only);
  if (!write_) write_.emplace(db_path_, OpenMode::existing);
  if (!pg_) {
    pg_.emplace(target_);
    require_fleet_schema(*pg_);
  }
}

PassResult Forwarder::pass(std::int64_t max_items) {
  open();
  std::vector<std::pair<Item, std::int64_t>> pending;
  {
    auto st = read_->prepare(
        "SELECT item, local_id FROM fleet_outbox WHERE acked < changes ORDER BY CASE item WHEN "
        "'run' THEN 0 WHEN 'fit' THEN 1 WHEN 'release' THEN 2 ELSE 3 END, local_id LIMIT ?");
    st.bind(1, max_items);
    while (st.step())
      pending.emplace_back(static_cast<Item>(item_order(st.column_text(0))), st.column_int(1));
  }
  PassResult r;
  r.more = static_cast<std::int64_t>(pending.size()) == max_items;
  for (const auto& [item, id] : pending) {
    try {
      const Sent sent = send_item(item, id);
      r.rows += sent.rows;
      r.appended += sent.appended;
      if (sent.complete) ++r.items;
      r.more = r.more || !sent.complete;
    } catch (const PgError& e) {
      if (!pg_->ok()) {  // the link, not the data: nothing more this pass
        pg_.reset();
        throw;
      }
      ++r.failed;
      r.last_error = e.what();
      record_error(item, id, e.what());
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
  if (item == Item::run) {
    sent = send_run(local_id);
  } else {
    PgTransaction tx(*pg_);
    for (const auto& t : fleet_tables())
      if (t.item == item) sent.rows += merge_all(t, local_id, {});
    tx.commit();
  }
  acknowledge(item, local_id, changes, sent);
  return sent;
}

std::int64_t Forwarder::merge_all(const FleetTable& t, std::int64_t local_id,
                                  const std::string& run_uuid) {
  auto st = read_->prepare(t.select);
  bind_named(st, ":id", local_id);
  bind_named(st, ":station", std::string_view(options_.station));
  return stage_and_merge(*pg_, t, encode_rows(st), run_uuid);
}

Forwarder::Sent Forwarder::send_run(std::int64_t run_id) {
  auto u = read_->prepare("SELECT uuid FROM runs WHERE id = ?");
  u.bind(1, run_id);
  if (!u.step() || u.column_is_null(0))
    throw PgError(fmt::format("run {}: no such run, or no uuid (schema older than 7?)", run_id));
  const std::string uuid = u.column_text(0);
  Sent sent;
  std::int64_t budget = options_.batch_rows;
  PgTransaction tx(*pg_);
  for (const auto& t : fleet_tables()) {
    if (t.item != Item::run || t.merge == Merge::append) continue;
    sent.rows += merge_all(t, run_id, uuid);
  }
  sent.rows += append_events(run_id, uuid, sent, budget);
  if (options_.samples) sent.rows += append_samples(run_id, uuid, sent, budget);
  tx.commit();
  return sent;
}

std::int64_t Forwarder::append_events(std::int64_t run_id, const std::string& run_uuid, Sent& sent,
                                      std::int64_t& budget) {
  const auto& t = fleet_table("events");
  auto have =
      pg_->exec("SELECT coalesce(max(local_id), 0) FROM events WHERE run_uuid = $1", {run_uuid});
  const std::int64_t after = have.integer(0, 0);
  auto st = read_->prepare(t.select);
  bind_named(st, ":id", run_id);
  bind_named(st, ":after", after);
  bind_named(st, ":limit", budget);
  const auto rows = encode_rows(st, 1);
  budget -= rows.rows;
  sent.appended += rows.rows;
  if (budget <= 0) sent.complete = false;
  sent.events_after = rows.last ? static_cast<std::int64_t>(*rows.last) : after;
  return stage_and_merge(*pg_, t, rows, run_uuid);
}

std::int64_t Forwarder::append_samples(std::int64_t run_id, const std::string& run_uuid, Sent& sent,
                                       std::int64_t& budget) {
  const auto& t = fleet_table("samples");
  auto serials = read_->prepare("SELECT serial FROM run_slots WHERE run_id = ? ORDER BY slot");
  serials.bind(1, run_id);
  std::int64_t changed = 0;
  std::optional<double> lowest;
  while (serials.step()) {
    const std::string serial = serials.column_text(0);
    auto have = pg_->exec("SELECT max(t_s) FROM samples WHERE run_uuid = $1 AND serial = $2",
                          {run_uuid, serial});
    const double after = have.is_null(0, 0) ? kBeforeAnySample : have.number(0, 0);
    if (budget <= 0) {
      sent.complete = false;
      lowest = lowest ? std::min(*lowest, after) : after;
      continue;
    }
    auto st = read_->prepare(t.select);
    bind_named(st, ":id", run_id);
    bind_named(st, ":serial", std::string_view(serial));
    bind_named(st, ":after", after);
    bind_named(st, ":limit", budget);
    const auto rows = encode_rows(st, 2);
    budget -= rows.rows;
    sent.appended += rows.rows;
    if (budget <= 0) sent.complete = false;
    const double reached = rows.last.value_or(after);
    lowest = lowest ? std::min(*lowest, reached) : reached;
    changed += stage_and_merge(*pg_, t, rows, run_uuid);
  }
  sent.samples_after = lowest;
  return changed;
}

void Forwarder::acknowledge(Item item, std::int64_t local_id, std::int64_t changes,
                            const Sent& sent) {
  auto st = write_->prepare(
      "UPDATE fleet_outbox SET acked = CASE WHEN ?1 THEN max(acked, ?2) ELSE acked END, "
      "acked_utc = ?3, events_acked_id = coalesce(?4, events_acked_id), "
      "samples_acked_t_s = coalesce(?5, samples_acked_t_s), last_error = NULL "
      "WHERE item = ?6 AND local_id = ?7");
  st.bind(1, sent.complete ? 1 : 0).bind(2, changes).bind(3, utc_now());
  if (sent.events_after)
    st.bind(4, *sent.events_after);
  else
    st.bind_null(4);
  st.bind(5, sent.samples_after);
  st.bind(6, item_name(item)).bind(7, local_id);
  st.step();
}

void Forwarder::record_error(Item item, std::int64_t local_id, const std::string& error) {
  auto st =
      write_->prepare("UPDATE fleet_outbox SET last_error = ? WHERE item = ? AND local_id = ?");
  st.bind(1, error).bind(2, item_name(item)).bind(3, local_id);
  st.step();
}

Backlog Forwarder::backlog() {
  if (!read_) read_.emplace(db_path_, OpenMode::read_only);
  ReadSnapshot snap(*read_);
  Backlog b;
  auto n = read_->prepare(
      "SELECT count(*) FILTER (WHERE item = 'run'), count(*) FROM fleet_outbox WHERE acked < "
      "changes");
  n.step();
  b.runs = n.column_int(0);
  b.items = n.column_int(1);
  auto rows = read_->prepare(fmt::format(
      "SELECT coalesce(sum((SELECT count(*) FROM events AS e WHERE e.run_id = o.local_id AND "
      "e.id > coalesce(o.events_acked_id, 0)){}), 0) FROM fleet_outbox AS o WHERE o.item = 'run' "
      "AND o.acked < o.changes",
      options_.samples ? " + (SELECT count(*) FROM samples AS s WHERE s.run_id = o.local_id AND "
                         "s.t_s > coalesce(o.samples_acked_t_s, -1e300))"
                       : ""));
  rows.step();
  b.rows = b.items + rows.column_int(0);
  return b;
}

}  // namespace station::fleet
