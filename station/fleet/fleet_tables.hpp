// What travels to the fleet's PostgreSQL, table by table: the one place that says which SQLite
// rows become which central rows (schemas/fleet/*.sql), how they are keyed and how a resend
// merges. A test checks these lists against both schemas (tests/fleet/test_fleet_schema.cpp).
#pragma once

#include <string_view>
#include <vector>

namespace station::fleet {

/// How a table's rows merge on the server.
enum class Merge {
  upsert,       ///< insert, or update a row whose content differs (a run's state, a fit's verdict)
  replace_set,  ///< upsert, then delete the run's central rows the station no longer has (bins
                ///< re-binned by `station fit`)
  append,       ///< insert new rows only, from a watermark (events, samples); never updated
};

/// The outbox item a table's rows belong to (fleet_outbox.item, migration 007).
enum class Item { run, fit, release, verification };
std::string_view item_name(Item i);

struct FleetTable {
  std::string_view name;     ///< the central table
  Item item;                 ///< whose rows these are
  std::string_view columns;  ///< central columns, comma-separated, in the SELECT's order
  std::string_view key;      ///< central key columns, comma-separated
  /// SQLite SELECT of those columns; named parameters :id (the item's local id), and for
  /// append tables :after (watermark), :limit, and for samples :serial.
  std::string_view select;
  Merge merge;
};

/// Every forwarded table, in the order one item's rows are sent.
const std::vector<FleetTable>& fleet_tables();
/// The table named `name` (throws std::out_of_range).
const FleetTable& fleet_table(std::string_view name);
/// `columns` or `key` split at commas.
std::vector<std::string_view> split_columns(std::string_view list);

}  // namespace station::fleet
