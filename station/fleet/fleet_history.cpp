#include "station/fleet/fleet_history.hpp"

#include <nlohmann/json.hpp>

namespace station::fleet {
namespace {

using nlohmann::json;

std::vector<SerialRun> runs_of(PgConnection& pg, const std::string& serial) {
  auto r = pg.exec(
      "SELECT r.fleet_id, r.started_utc, coalesce(r.ended_utc, ''), r.state, r.protocol_name, "
      "r.station, r.operator, s.slot, s.part_number FROM runs AS r JOIN run_slots AS s ON "
      "s.run_uuid = r.uuid WHERE s.serial = $1 ORDER BY r.started_utc, r.fleet_id",
      {serial});
  std::vector<SerialRun> out;
  for (int i = 0; i < r.rows(); ++i) {
    SerialRun x;
    x.run_id = r.integer(i, 0);
    x.started_utc = r.text(i, 1);
    x.ended_utc = r.text(i, 2);
    x.state = r.text(i, 3);
    x.protocol_name = r.text(i, 4);
    x.station = r.text(i, 5);
    x.operator_name = r.text(i, 6);
    x.slot = static_cast<int>(r.integer(i, 7));
    x.part_number = r.opt_text(i, 8);
    out.push_back(std::move(x));
  }
  return out;
}

// The fit's runs by fleet id: run_uuids_json mapped through the central runs (a run not yet
// arrived is left out).
std::vector<SerialFitRow> fits_of(PgConnection& pg, const std::string& serial) {
  auto r = pg.exec(
      "SELECT f.fleet_id, f.created_utc, f.terms, coalesce((SELECT json_agg(r.fleet_id ORDER BY "
      "r.fleet_id) FROM json_array_elements_text(f.run_uuids_json::json) AS u JOIN runs AS r ON "
      "r.uuid = u::uuid), '[]'), f.coefficients_json, f.std_errors_json, f.n_bins, f.std_ratio, "
      "f.std_after_dph, f.part_number, f.verdict_json, f.station FROM fits AS f WHERE f.serial = "
      "$1 ORDER BY f.created_utc, f.fleet_id",
      {serial});
  std::vector<SerialFitRow> out;
  for (int i = 0; i < r.rows(); ++i) {
    SerialFitRow f;
    f.fit_id = r.integer(i, 0);
    f.created_utc = r.text(i, 1);
    f.terms = r.text(i, 2);
    f.runs = json::parse(r.text(i, 3)).get<std::vector<std::int64_t>>();
    f.coefficients = values_by_name(r.text(i, 4));
    f.std_errors = values_by_name(r.text(i, 5));
    f.n_bins = r.integer(i, 6);
    if (!r.is_null(i, 7)) f.std_ratio = r.number(i, 7);
    f.std_after_dph = r.number(i, 8);
    f.part_number = r.opt_text(i, 9);
    f.verdict_json = r.opt_text(i, 10);
    f.station = r.text(i, 11);
    out.push_back(std::move(f));
  }
  return out;
}

std::vector<ReleaseRow> releases_of(PgConnection& pg, const std::string& serial) {
  auto r = pg.exec(
      "SELECT coalesce(f.fleet_id, 0), l.serial, l.released_utc, l.released_by, l.note, "
      "l.override_reason, l.verdict_json, l.local_id FROM releases AS l LEFT JOIN fits AS f ON "
      "f.uuid = l.fit_uuid WHERE l.serial = $1 ORDER BY l.released_utc, l.station, l.local_id",
      {serial});
  std::vector<ReleaseRow> out;
  for (int i = 0; i < r.rows(); ++i) {
    ReleaseRow x;
    x.fit_id = r.integer(i, 0);
    x.serial = r.text(i, 1);
    x.released_utc = r.text(i, 2);
    x.released_by = r.text(i, 3);
    x.note = r.text(i, 4);
    x.override_reason = r.opt_text(i, 5);
    x.verdict_json = r.opt_text(i, 6);
    x.id = r.integer(i, 7);
    out.push_back(std::move(x));
  }
  return out;
}

}  // namespace

FleetSerialHistory fleet_serial_history(PgConnection& pg, const std::string& serial) {
  return {runs_of(pg, serial), fits_of(pg, serial), releases_of(pg, serial)};
}

}  // namespace station::fleet
