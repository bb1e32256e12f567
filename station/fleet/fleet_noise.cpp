#include "station/fleet/fleet_noise.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "station/report/report_allan.hpp"
#include "station/store/calibration.hpp"

namespace station::fleet {
namespace {

namespace sc = station::compensation;
using nlohmann::json;

/// The stored fit's model: terms, T_ref and coefficients by name (as store_fits reads a fit).
sc::FitResult stored_model(const std::string& terms, double ref_temp_c,
                           const std::string& coefficients_json) {
  sc::FitResult fit;
  fit.spec = sc::ModelSpec{sc::parse_terms(terms), ref_temp_c};
  const json coef = json::parse(coefficients_json);
  fit.names.emplace_back("B0");
  for (const auto t : fit.spec.terms) fit.names.emplace_back(sc::term_coefficient_name(t));
  for (const auto& n : fit.names) fit.coefficients.push_back(coef.at(n).get<double>());
  return fit;
}

/// The run's bin width: the store's rule (store/calibration.hpp) on the central resolved_json.
double bin_s_of(const std::optional<std::string>& resolved_json) {
  RunRecord run;
  run.resolved_json = resolved_json.value_or("{}");
  return run_bin_s(run);
}

std::vector<SampleRow> samples_of(PgConnection& pg, const std::string& run_uuid,
                                  const std::string& serial) {
  auto r = pg.exec(
      "SELECT t_s, rate_dph, temp_c, temp2_c, flags, recording FROM samples WHERE run_uuid = "
      "$1::uuid AND serial = $2 ORDER BY t_s",
      {run_uuid, serial});
  std::vector<SampleRow> out(static_cast<std::size_t>(r.rows()));
  for (int i = 0; i < r.rows(); ++i) {
    auto& s = out[static_cast<std::size_t>(i)];
    s.serial = serial;
    s.t_s = r.number(i, 0);
    if (!r.is_null(i, 1)) s.rate_dph = r.number(i, 1);
    if (!r.is_null(i, 2)) s.temp_c = r.number(i, 2);
    if (!r.is_null(i, 3)) s.temp2_c = r.number(i, 3);
    s.flags = static_cast<int>(r.integer(i, 4));
    s.recording = r.integer(i, 5) != 0;
  }
  return out;
}

/// One (run, serial) row of the query in fleet_run_noise, estimated.
RunNoise run_noise_of(PgConnection& pg, const PgResult& r, int i) {
  RunNoise n;
  n.part = r.text(i, 0);
  n.serial = r.text(i, 1);
  n.fit_fleet_id = r.integer(i, 2);
  n.run_uuid = r.text(i, 3);
  n.station = r.opt_text(i, 7).value_or(r.text(i, 10));
  if (r.is_null(i, 7)) {
    n.problem = "the run is not in the fleet database (not yet arrived)";
    return n;
  }
  if (r.is_null(i, 9)) {
    n.problem = "the run has no slot of this serial: its Earth rate is unknown";
    return n;
  }
  sc::FitResult fit;
  try {
    fit = stored_model(r.text(i, 4), r.number(i, 5), r.text(i, 6));
  } catch (const std::exception& e) {
    n.problem = fmt::format("the fit's model cannot be read: {}", e.what());
    return n;
  }
  const auto samples = samples_of(pg, n.run_uuid, n.serial);
  return estimate_run_noise(std::move(n), samples, r.number(i, 9), fit, bin_s_of(r.opt_text(i, 8)));
}

}  // namespace

RunNoise estimate_run_noise(RunNoise r, const std::vector<SampleRow>& samples,
                            double earth_rate_dph, const sc::FitResult& fit, double bin_s) {
  if (samples.empty()) {
    r.problem = "no 1 Hz samples in the fleet database (the station forwards without samples)";
    return r;
  }
  try {
    const auto record = report::one_hz_record(samples, earth_rate_dph, fit, bin_s);
    r.samples = record.compensated_dph.size();
    if (r.samples < kMinNoiseSamples) {
      r.problem = fmt::format("{} usable samples in the record window: an estimate needs {}",
                              r.samples, kMinNoiseSamples);
      return r;
    }
    const auto terms = report::allan_curves(record).noise_after;
    if (!terms.angle_random_walk_deg_rth || !(*terms.angle_random_walk_deg_rth > 0)) {
      r.problem = "the Allan curve of the compensated record has no ARW term";
      return r;
    }
    r.terms = terms;
  } catch (const std::exception& e) {  // DataError: a sample the Allan variance cannot take
    r.problem = fmt::format("the compensated record: {}", e.what());
  }
  return r;
}

std::vector<RunNoise> fleet_run_noise(PgConnection& pg, const ChartFilter& f) {
  // Per run and serial the newest fit that used the run (its model compensates the record).
  auto r = pg.exec(
      "SELECT DISTINCT ON (u.run_uuid, f.serial) f.part_number, f.serial, f.fleet_id, "
      "u.run_uuid, f.terms, f.ref_temp_c, f.coefficients_json, r.station, r.resolved_json, "
      "s.earth_rate_dph, f.station FROM fits AS f CROSS JOIN LATERAL "
      "json_array_elements_text(f.run_uuids_json::json) AS u(run_uuid) LEFT JOIN runs AS r ON "
      "r.uuid = u.run_uuid::uuid LEFT JOIN run_slots AS s ON s.run_uuid = r.uuid AND s.serial = "
      "f.serial WHERE f.part_number IS NOT NULL AND ($1::text IS NULL OR f.part_number = $1) AND "
      "($2::text IS NULL OR f.created_utc >= $2) "
      "ORDER BY u.run_uuid, f.serial, f.created_utc DESC, f.fleet_id DESC",
      {f.part, f.since});
  std::vector<RunNoise> out;
  for (int i = 0; i < r.rows(); ++i) out.push_back(run_noise_of(pg, r, i));
  return out;
}

}  // namespace station::fleet
