// Applying a stored fit to an independent run, judging and storing the result.
#include "station/release/verification.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "compensation/adev_floor.hpp"
#include "station/release/coefficient_block.hpp"
#include "station/store/calibration.hpp"

namespace station {
namespace {

namespace sc = station::compensation;
using nlohmann::json;

void check_run(Store& store, const FitRecord& fit, std::int64_t run_id) {
  if (!store.find_run(run_id))
    throw InputError(fmt::format("{}: no run {}", store.db().path(), run_id));
  if (std::find(fit.runs.begin(), fit.runs.end(), run_id) != fit.runs.end())
    throw InputError(fmt::format(
        "verify: run {} is one of the runs fit {} was fitted on ({}): verify on a run it did not "
        "see",
        run_id, fit.id, fmt::join(fit.runs, ",")));
  const auto slots = store.run_slots(run_id);
  if (std::none_of(slots.begin(), slots.end(),
                   [&](const RunSlot& s) { return s.serial == fit.serial; }))
    throw InputError(fmt::format("{}: run {} did not record serial '{}'", store.db().path(), run_id,
                                 fit.serial));
}

/// Slope of `after` against T and its honest SE (the station's own fit, terms dT), under the
/// part's noise the verified fit was made with (a prior on the error model: noise_prior.hpp).
void fit_drift(const sc::ModelData& bins, const std::vector<double>& after, double t_ref_c,
               const std::optional<sc::NoisePrior>& prior, VerificationResult& v) {
  sc::ModelData d = bins;
  d.bias_dph = after;
  try {
    const sc::FitResult line = sc::fit_model(d.view(), {{sc::Term::dT}, t_ref_c, prior});
    v.drift_dph_per_c = line.coefficients[1];
    v.drift_se_dph_per_c = line.std_errors[1];
  } catch (const std::exception&) {
    // Too few bins or constant T: no drift figure rather than an invented one.
  }
}

/// The verdict of `limits` on v's figures (fewer than kMinVerifyBins bins: cannot be shown, so
/// every limit fails, verdict.hpp's rule).
std::optional<Verdict> judge(const PartLimits& limits, const VerificationResult& v) {
  VerificationFigures fig{v.eval.std_after_dph, v.eval.std_ratio};
  if (v.bins < kMinVerifyBins) fig = {NAN, std::nullopt};
  return judge_verification(limits, fig);
}

}  // namespace

VerificationResult verify_fit(Store& store, const FitRecord& fit, std::int64_t run_id,
                              const std::optional<PartLimits>& limits) {
  check_run(store, fit, run_id);
  const CoefficientBlock block = make_block(store, fit, std::nullopt);
  const gyro_tc_block c = block.c_block();
  const sc::ModelData bins = store.model_data(fit.serial, {run_id});
  if (bins.bias_dph.empty())
    throw InputError(fmt::format("{}: run {} has no complete bin of '{}' (was it binned?)",
                                 store.db().path(), run_id, fit.serial));
  VerificationResult v;
  v.serial = fit.serial;
  v.fit_id = fit.id;
  v.run_id = run_id;
  v.bins = bins.bias_dph.size();
  for (std::size_t i = 0; i < v.bins; ++i) {
    const double t = bins.temp_c[i], g = bins.grad_c[i];
    v.after_dph.push_back(gyro_tc_correct(&c, bins.bias_dph[i], t, g));
    if (t < c.t_min_c || t > c.t_max_c || g < c.grad_min_c || g > c.grad_max_c) ++v.clamped_bins;
  }
  v.t_s = bins.t_mid_s;
  v.temp_c = bins.temp_c;
  v.before_dph = bins.bias_dph;
  v.eval = sc::evaluate(v.before_dph, v.after_dph);
  v.mean_residual_dph =
      std::accumulate(v.after_dph.begin(), v.after_dph.end(), 0.0) / static_cast<double>(v.bins);
  fit_drift(bins, v.after_dph, block.t_ref_c, fit.fit.spec.noise_prior, v);
  const sc::ModelData rec = record_model_data(store, run_id, fit.serial);
  std::vector<double> record(rec.bias_dph.size());
  for (std::size_t i = 0; i < record.size(); ++i)
    record[i] = gyro_tc_correct(&c, rec.bias_dph[i], rec.temp_c[i], rec.grad_c[i]);
  if (const auto floor = sc::adev_floor(record, 1.0)) v.adev_floor_dph = floor->adev;
  const auto run = store.find_run(run_id);
  if (run && run->state != RunState::completed)
    v.warnings.push_back(
        fmt::format("run {} ended '{}', not completed", run_id, to_string(run->state)));
  const bool enough = v.bins >= kMinVerifyBins;
  if (!enough)
    v.warnings.push_back(
        fmt::format("only {} complete bins (fewer than {}): the figures say "
                    "little and every verification limit fails",
                    v.bins, kMinVerifyBins));
  if (limits) {
    v.part_number = limits->number;
    v.verdict = judge(*limits, v);
    if (!v.verdict)
      v.warnings.push_back(
          fmt::format("part {} sets no verification limit (max_verify_std_dph, "
                      "max_verify_ratio): no verdict",
                      limits->number));
  }
  return v;
}

json verification_json(const VerificationResult& v) {
  const auto opt = [](const std::optional<double>& x) { return x ? json(*x) : json(nullptr); };
  return {{"serial", v.serial},
          {"fit_id", v.fit_id},
          {"run_id", v.run_id},
          {"bins", v.bins},
          {"std_before_dph", v.eval.std_before_dph},
          {"std_after_dph", v.eval.std_after_dph},
          {"ratio", opt(v.eval.std_ratio)},
          {"mean_residual_dph", v.mean_residual_dph},
          {"drift_dph_per_c", opt(v.drift_dph_per_c)},
          {"drift_se_dph_per_c", opt(v.drift_se_dph_per_c)},
          {"adev_floor_dph", opt(v.adev_floor_dph)},
          {"clamped_bins", v.clamped_bins},
          {"part_number", v.part_number ? json(*v.part_number) : json(nullptr)},
          {"verdict", v.verdict ? verdict_json(*v.verdict) : json(nullptr)},
          {"warnings", v.warnings}};
}

std::int64_t save_verification(Store& store, VerificationResult& v) {
  Transaction tx(store.db());
  v.created_utc = utc_now_iso();
  auto st = store.db().prepare(
      "INSERT INTO verifications (fit_id, run_id, serial, created_utc, result_json, part_number, "
      "verdict_json) VALUES (?,?,?,?,?,?,?)");
  st.bind(1, v.fit_id).bind(2, v.run_id).bind(3, v.serial).bind(4, v.created_utc);
  st.bind(5, verification_json(v).dump());
  v.part_number ? st.bind(6, *v.part_number) : st.bind_null(6);
  v.verdict ? st.bind(7, verdict_json(*v.verdict).dump()) : st.bind_null(7);
  st.step();
  v.id = store.db().last_insert_id();
  const auto run = store.find_run(v.run_id);
  const bool failed = v.verdict && !v.verdict->pass;
  store.add_event(
      v.run_id, run && run->last_tick_s ? *run->last_tick_s : 0.0,
      failed ? Severity::warn : Severity::info, "verify", EventKind::verification,
      fmt::format("{}: fit {} applied to this run: std {:.5f} -> {:.5f} deg/h, {}", v.serial,
                  v.fit_id, v.eval.std_before_dph, v.eval.std_after_dph, verdict_text(v.verdict)),
      json{{"verification_id", v.id}, {"fit_id", v.fit_id}});
  tx.commit();
  return v.id;
}

std::vector<VerificationResult> verifications_of_run(Store& store, std::int64_t run_id) {
  auto st = store.db().prepare(
      "SELECT id, serial, fit_id, created_utc, result_json, part_number, verdict_json FROM "
      "verifications WHERE run_id = ? ORDER BY id");
  st.bind(1, run_id);
  std::vector<VerificationResult> out;
  while (st.step()) {
    VerificationResult v;
    v.id = st.column_int(0);
    v.serial = st.column_text(1);
    v.fit_id = st.column_int(2);
    v.run_id = run_id;
    v.created_utc = st.column_text(3);
    const json r = json::parse(st.column_text(4));
    v.bins = r.value("bins", std::size_t{0});
    v.eval.std_before_dph = r.value("std_before_dph", 0.0);
    v.eval.std_after_dph = r.value("std_after_dph", 0.0);
    if (r.contains("ratio") && r["ratio"].is_number()) v.eval.std_ratio = r["ratio"].get<double>();
    v.mean_residual_dph = r.value("mean_residual_dph", 0.0);
    for (auto [key, dst] : {std::pair{"drift_dph_per_c", &v.drift_dph_per_c},
                            {"drift_se_dph_per_c", &v.drift_se_dph_per_c},
                            {"adev_floor_dph", &v.adev_floor_dph}})
      if (r.contains(key) && r[key].is_number()) *dst = r[key].get<double>();
    v.clamped_bins = r.value("clamped_bins", std::size_t{0});
    v.warnings = r.value("warnings", std::vector<std::string>{});
    if (!st.column_is_null(5)) v.part_number = st.column_text(5);
    if (!st.column_is_null(6)) v.verdict = verdict_from_json(json::parse(st.column_text(6)));
    out.push_back(std::move(v));
  }
  return out;
}

std::optional<VerificationResult> stored_verification(Store& store, std::int64_t fit_id,
                                                      std::int64_t run_id,
                                                      const std::optional<PartLimits>& limits) {
  const std::optional<std::string> part =
      limits ? std::optional<std::string>(limits->number) : std::nullopt;
  auto all = verifications_of_run(store, run_id);
  for (auto it = all.rbegin(); it != all.rend(); ++it) {
    if (it->fit_id != fit_id || it->part_number != part) continue;
    const auto now = limits ? judge(*limits, *it) : std::nullopt;
    const auto as_json = [](const std::optional<Verdict>& v) {
      return v ? verdict_json(*v) : json(nullptr);
    };
    if (as_json(now) == as_json(it->verdict)) return std::move(*it);
  }
  return std::nullopt;
}

}  // namespace station
