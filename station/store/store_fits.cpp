// Store: bins and fits (the bin table of migration 1, the fit columns of migrations 3, 4 and 8).
#include <algorithm>
#include <nlohmann/json.hpp>

#include "compensation/earth_rate.hpp"
#include "station/store/fit_bins.hpp"
#include "station/store/fit_json.hpp"
#include "station/store/store.hpp"

namespace station {

namespace sc = station::compensation;
using nlohmann::json;

void Store::replace_bins(std::int64_t run_id, const std::string& serial,
                         const std::vector<sc::Bin>& bins, double earth_rate_dph) {
  flush();
  Transaction tx(db_);
  auto del = db_.prepare("DELETE FROM bins WHERE run_id = ? AND serial = ?");
  del.bind(1, run_id).bind(2, serial);
  del.step();
  auto ins = db_.prepare(
      "INSERT INTO bins (run_id, serial, t_start_s, n, rate_dph, bias_dph, temp_c, grad_c, "
      "dtdt_c_per_h, complete, temp_min_c, temp_max_c, grad_min_c, grad_max_c) "
      "VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?)");
  for (const auto& b : bins) {
    ins.bind(1, run_id)
        .bind(2, serial)
        .bind(3, b.t_start_s)
        .bind(4, static_cast<std::int64_t>(b.n));
    ins.bind(5, b.rate_dph).bind(6, sc::bias_dph(b.rate_dph, earth_rate_dph)).bind(7, b.temp_c);
    ins.bind(8, b.grad_c).bind(9, b.dtdt_c_per_h).bind(10, b.complete ? 1 : 0);
    ins.bind(11, b.temp_min_c).bind(12, b.temp_max_c).bind(13, b.grad_min_c);
    ins.bind(14, b.grad_max_c);
    ins.step();
    ins.reset();
  }
  tx.commit();
}

FitBins fit_bins(Store& store, const std::string& serial, const std::vector<std::int64_t>& runs) {
  // One read of the bins for the data and their span (issue 37: reading them twice, the span by
  // an aggregate query per run, was 6 % of `fit --all`).
  FitBins out;
  sc::ModelData& d = out.data;
  auto lease = store.cached(
      "SELECT bias_dph, temp_c, grad_c, dtdt_c_per_h, t_start_s, temp_min_c, temp_max_c, "
      "grad_min_c, grad_max_c FROM bins WHERE run_id = ? AND serial = ? AND complete = 1 "
      "ORDER BY t_start_s");
  Statement& st = *lease;
  bool spanned = true;  // false: a bin from before migration 8 (its ranges NULL)
  for (std::size_t k = 0; k < runs.size(); ++k) {
    st.bind(1, runs[k]).bind(2, serial);
    while (st.step()) {
      d.segment.push_back(static_cast<int>(k));
      d.bias_dph.push_back(st.column_double(0));
      d.temp_c.push_back(st.column_double(1));
      d.grad_c.push_back(st.column_double(2));
      d.dtdt_c_per_h.push_back(st.column_double(3));
      d.channel.push_back(0.0);
      d.t_mid_s.push_back(st.column_double(4));
      if (!spanned) continue;
      for (int c = 5; c <= 8; ++c) spanned = spanned && !st.column_is_null(c);
      if (!spanned) continue;
      const FitSpan s{st.column_double(5), st.column_double(6), st.column_double(7),
                      st.column_double(8)};
      out.span = out.span ? FitSpan{std::min(out.span->temp_min_c, s.temp_min_c),
                                    std::max(out.span->temp_max_c, s.temp_max_c),
                                    std::min(out.span->grad_min_c, s.grad_min_c),
                                    std::max(out.span->grad_max_c, s.grad_max_c)}
                          : s;
    }
    st.reset();
  }
  if (!spanned) out.span.reset();
  return out;
}

sc::ModelData Store::model_data(const std::string& serial, const std::vector<std::int64_t>& runs) {
  return fit_bins(*this, serial, runs).data;
}

std::optional<FitSpan> Store::bins_span(const std::string& serial,
                                        const std::vector<std::int64_t>& runs) {
  return fit_bins(*this, serial, runs).span;
}

std::vector<std::int64_t> Store::runs_of_serial(const std::string& serial) {
  // Migration 14's index run_slots_by_serial answers it without a scan of the table.
  auto st = cached("SELECT DISTINCT run_id FROM run_slots WHERE serial = ? ORDER BY run_id");
  st->bind(1, serial);
  std::vector<std::int64_t> out;
  while (st->step()) out.push_back(st->column_int(0));
  return out;
}

std::int64_t Store::save_fit(const std::string& serial, const std::vector<std::int64_t>& runs,
                             const sc::FitResult& fit, const sc::Evaluation& eval,
                             const std::optional<FitSpan>& span) {
  const json coef = coefficients_json(fit), se = std_errors_json(fit);
  std::string terms;
  for (auto t : fit.spec.terms)
    terms += (terms.empty() ? "" : ",") + std::string(sc::term_option_name(t));
  // Prepared once per Store (fit --all stores a thousand fits: preparing each was ~10 % of it).
  auto lease = cached(
      "INSERT INTO fits (serial, created_utc, runs_json, terms, ref_temp_c, coefficients_json, "
      "std_errors_json, n_bins, r2, residual_rms_dph, condition_number, std_before_dph, "
      "std_after_dph, std_ratio, warnings_json, std_errors_ols_json, error_model_json, "
      "temp_min_c, temp_max_c, grad_min_c, grad_max_c) "
      "VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)");
  Statement& st = *lease;
  st.bind(1, serial).bind(2, utc_now_iso()).bind(3, json(runs).dump()).bind(4, terms);
  st.bind(5, fit.spec.ref_temp_c).bind(6, coef.dump()).bind(7, se.dump());
  st.bind(8, static_cast<std::int64_t>(fit.n_points))
      .bind(9, fit.r2)
      .bind(10, fit.residual_rms_dph);
  st.bind(11, fit.condition_number).bind(12, eval.std_before_dph).bind(13, eval.std_after_dph);
  st.bind(14, eval.std_ratio).bind(15, json(fit.warnings).dump());
  st.bind(16, std_errors_ols_json(fit).dump()).bind(17, fit_error_model_json(fit).dump());
  for (int c = 18; c <= 21; ++c) st.bind_null(c);
  if (span) st.bind(18, span->temp_min_c).bind(19, span->temp_max_c);
  if (span) st.bind(20, span->grad_min_c).bind(21, span->grad_max_c);
  st.step();
  return db_.last_insert_id();
}

namespace {
constexpr const char* kFitColumns =
    "SELECT id, created_utc, runs_json, terms, ref_temp_c, coefficients_json, std_errors_json, "
    "n_bins, r2, residual_rms_dph, condition_number, std_before_dph, std_after_dph, std_ratio, "
    "warnings_json, std_errors_ols_json, error_model_json, serial, temp_min_c, temp_max_c, "
    "grad_min_c, grad_max_c FROM fits ";

FitRecord read_fit(const Statement& st) {
  FitRecord r;
  r.id = st.column_int(0);
  r.serial = st.column_text(17);
  r.created_utc = st.column_text(1);
  r.runs = json::parse(st.column_text(2)).get<std::vector<std::int64_t>>();
  r.terms = st.column_text(3);
  r.fit.spec = sc::ModelSpec{sc::parse_terms(r.terms), st.column_double(4)};
  const json coef = json::parse(st.column_text(5)), se = json::parse(st.column_text(6));
  r.fit.names.emplace_back("B0");
  for (auto t : r.fit.spec.terms) r.fit.names.emplace_back(sc::term_coefficient_name(t));
  for (const auto& n : r.fit.names) {
    r.fit.coefficients.push_back(coef.at(n).get<double>());
    r.fit.std_errors.push_back(se.at(n).get<double>());
  }
  r.fit.n_points = static_cast<std::size_t>(st.column_int(7));
  r.fit.r2 = st.column_double(8);
  r.fit.residual_rms_dph = st.column_double(9);
  r.fit.condition_number = st.column_double(10);
  r.eval.std_before_dph = st.column_double(11);
  r.eval.std_after_dph = st.column_double(12);
  if (!st.column_is_null(13)) {  // NULL: the ratio is undefined (std before at rounding level)
    r.eval.std_ratio = st.column_double(13);
    r.eval.improvement_pct = 100.0 * (1.0 - *r.eval.std_ratio);
  }
  r.fit.warnings = json::parse(st.column_text(14)).get<std::vector<std::string>>();
  const json se_ols = json::parse(st.column_text(15));
  for (const auto& n : r.fit.names) {
    if (se_ols.is_object()) r.fit.std_errors_ols.push_back(se_ols.at(n).get<double>());
  }
  const json em = json::parse(st.column_text(16));
  r.fit.error_model = error_model_from_json(em);
  r.fit.spec.noise_prior = r.fit.error_model.prior;
  read_walk_not_excluded(em, r.fit);
  if (!st.column_is_null(18) && !st.column_is_null(19) && !st.column_is_null(20) &&
      !st.column_is_null(21))
    r.span = FitSpan{st.column_double(18), st.column_double(19), st.column_double(20),
                     st.column_double(21)};
  return r;
}
}  // namespace

std::optional<FitRecord> Store::latest_fit(const std::string& serial) {
  auto st = db_.prepare(std::string(kFitColumns) + "WHERE serial = ? ORDER BY id DESC LIMIT 1");
  st.bind(1, serial);
  if (!st.step()) return std::nullopt;
  return read_fit(st);
}

std::optional<FitRecord> Store::find_fit(std::int64_t fit_id) {
  auto st = db_.prepare(std::string(kFitColumns) + "WHERE id = ?");
  st.bind(1, fit_id);
  if (!st.step()) return std::nullopt;
  return read_fit(st);
}

std::optional<FitRecord> Store::latest_fit_of_run(const std::string& serial, std::int64_t run_id) {
  auto st = db_.prepare(std::string(kFitColumns) +
                        "WHERE serial = ? AND EXISTS (SELECT 1 FROM json_each(fits.runs_json) "
                        "WHERE json_each.value = ?) ORDER BY id DESC LIMIT 1");
  st.bind(1, serial).bind(2, run_id);
  if (!st.step()) return std::nullopt;
  return read_fit(st);
}

}  // namespace station
