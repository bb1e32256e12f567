// Store and forward: sends what the station's SQLite holds and PostgreSQL does not yet, item by
// item (a run with its slots, bins, events and samples; a fit; a release; a verification), each
// in one PostgreSQL transaction, and records the acknowledgement in SQLite's fleet_outbox
// (migration 007) only after the server committed. Idempotent: central rows are keyed by uuids
// minted locally, appended rows resume from the server's own watermark, merged rows are only
// rewritten when they differ; a resend after a lost acknowledgement or a kill changes nothing.
// Reads through its own read-only connection (one snapshot per item); its only writes are the
// outbox's acknowledgements. Never touches the tick loop: `serve` runs it on its own thread
// (forwarder_thread.hpp), `station sync` once.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>

#include "station/config/fleet_config.hpp"
#include "station/fleet/copy_binary.hpp"
#include "station/fleet/fleet_tables.hpp"
#include "station/fleet/pg.hpp"
#include "station/store/sqlite.hpp"

namespace station::fleet {

struct ForwardOptions {
  bool samples = false;              ///< forward the 1 Hz samples too ([fleet] samples)
  std::int64_t batch_rows = 50'000;  ///< appended rows per PostgreSQL transaction
  std::string station;  ///< the station's name, for a fit whose runs are gone from the file
};

/// Where [fleet] says to connect.
inline PgTarget fleet_target(const FleetConfig& f) {
  return {f.pg, f.keywords, kPgConnectTimeoutS, f.timeout_s};
}

/// What is still to send.
struct Backlog {
  std::int64_t runs = 0;   ///< runs not acknowledged in their latest state
  std::int64_t items = 0;  ///< runs, fits, releases and verifications not acknowledged
  std::int64_t rows = 0;   ///< items plus the events (and samples, when forwarded) behind them
  std::int64_t held = 0;   ///< items held: the server has a newer state (a restored file)
};

/// Wall-clock now, Unix seconds (retry times in the outbox, the last success).
double unix_now_s();

/// The pause after a failure that followed a pause of `previous_s` (0: the first failure):
/// 0.5 s, doubling, at most 60 s (issue 24). For the link and for each refused item.
double next_backoff_s(double previous_s);

/// One pass.
struct PassResult {
  std::int64_t items = 0;     ///< items acknowledged complete
  std::int64_t rows = 0;      ///< rows PostgreSQL inserted or changed
  std::int64_t appended = 0;  ///< event and sample rows sent (each is sent once, resends none)
  std::int64_t failed = 0;    ///< items the server refused (their outbox row holds why)
  bool more = false;          ///< more to send right away (a batch limit was reached)
  std::string last_error;     ///< the last refusal, empty when none
  /// Adds another pass's counts (`more` is the other's; the last error the latest).
  PassResult& operator+=(const PassResult& o);
};

class Forwarder {
 public:
  /// No I/O: databases and the server are opened by the first pass.
  Forwarder(std::string db_path, PgTarget target, ForwardOptions options);
  /// Sends up to `max_items` pending items, stopping early once `stop` says so (checked
  /// between items). Throws PgError when the server cannot be reached, the link drops or its
  /// schema is older (nothing acknowledged that was not committed), SqliteError on a local
  /// fault. An item the server refuses, or holds a newer state of, is recorded in the outbox and
  /// the pass goes on.
  PassResult pass(std::int64_t max_items = 100, const std::function<bool()>& stop = {});
  /// Reads the outbox (no server needed; its own connection, so a wait inside a pass may ask).
  Backlog backlog();
  /// What the server connection's waits look at (a stop, a slow call): from the next connect.
  void set_watch(PgWatch watch) { watch_ = std::move(watch); }
  /// Drops the server connection (the next pass reconnects).
  void disconnect();
  /// Forwards held items again (`station sync --retry-held`): each is checked anew.
  void release_held();

 private:
  struct Sent {
    std::int64_t rows = 0;
    std::int64_t appended = 0;
    bool complete = true;
    std::optional<std::int64_t> events_after;
    std::optional<double> samples_after;
  };
  void open();
  Sent send_item(Item item, std::int64_t local_id);
  std::string send_item_row(Item item, std::int64_t local_id, Sent& sent);
  void send_run(std::int64_t run_id, const std::string& uuid, Sent& sent);
  void append_events(std::int64_t run_id, const std::string& run_uuid, Sent& sent,
                     std::int64_t& budget);
  void append_samples(std::int64_t run_id, const std::string& run_uuid, Sent& sent,
                      std::int64_t& budget);
  /// `binary`: the central columns' types, to send the rows in COPY's binary format.
  void append_from(const FleetTable& t, Statement& st, std::optional<double> mark, int mark_col,
                   Sent& sent, std::int64_t& budget, std::int64_t run_id,
                   std::optional<double>& reached, std::span<const PgType> binary = {});
  void acknowledge(Item item, std::int64_t local_id, std::int64_t changes, const Sent& sent);
  void record_error(Item item, std::int64_t local_id, const std::string& error, bool hold);

  std::string db_path_;
  PgTarget target_;
  ForwardOptions options_;
  std::optional<Database> read_, write_, count_;
  std::optional<PgConnection> pg_;
  PgWatch watch_;
  std::string identity_;  ///< the station's identity (station_identity.uuid, migration 10)
};

}  // namespace station::fleet
