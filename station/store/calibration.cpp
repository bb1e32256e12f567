// Binning stored runs and fitting per serial number with the compensation core.
#include "station/store/calibration.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "compensation/binning.hpp"
#include "compensation/earth_rate.hpp"
#include "station/common/input_error.hpp"
#include "station/store/fit_bins.hpp"
#include "station/store/sample_series.hpp"

namespace station {

namespace sc = station::compensation;

std::optional<double> recorded_bin_s(const RunRecord& run) {
  const auto j = nlohmann::json::parse(run.resolved_json, nullptr, false);
  if (!j.is_object() || !j.contains("bin_s") || !j["bin_s"].is_number()) return std::nullopt;
  const double bin_s = j["bin_s"].get<double>();
  if (!(bin_s > 0)) return std::nullopt;
  return bin_s;
}

double run_bin_s(const RunRecord& run) {
  return recorded_bin_s(run).value_or(sc::kPaperBinS);
}

sc::ModelData record_model_data(Store& store, std::int64_t run_id, const std::string& serial) {
  double earth_rate_dph = 0;
  for (const auto& s : store.run_slots(run_id))
    if (s.serial == serial) earth_rate_dph = s.earth_rate_dph;
  SampleSeries s = sample_series(store.samples(run_id, serial, true));
  sc::ModelData d;
  for (double r : s.rate_dph) d.bias_dph.push_back(sc::bias_dph(r, earth_rate_dph));
  d.temp_c = std::move(s.temp_c);
  d.grad_c = std::move(s.grad_c);
  d.t_mid_s = std::move(s.t_s);
  return d;
}

sc::ModelData fitted_record_model_data(Store& store, std::int64_t run_id,
                                       const std::string& serial) {
  const auto run = store.find_run(run_id);
  const double bin_s = run ? run_bin_s(*run) : sc::kPaperBinS;
  const std::vector<double> starts = store.model_data(serial, {run_id}).t_mid_s;  // bin starts
  const sc::ModelData all = record_model_data(store, run_id, serial);
  sc::ModelData d;
  for (std::size_t i = 0; i < all.bias_dph.size(); ++i) {
    const double t = all.t_mid_s[i];
    auto it = std::upper_bound(starts.begin(), starts.end(), t);  // first start after t
    if (it == starts.begin() || t >= *std::prev(it) + bin_s) continue;
    d.bias_dph.push_back(all.bias_dph[i]);
    d.temp_c.push_back(all.temp_c[i]);
    d.grad_c.push_back(all.grad_c[i]);
    d.t_mid_s.push_back(t);
  }
  return d;
}

std::vector<sc::Bin> bin_samples(const std::vector<SampleRow>& rows, double bin_s) {
  const SampleSeries s = sample_series(rows);
  sc::BinConfig cfg;
  cfg.width_s = bin_s;
  cfg.sample_period_s = 1.0;  // the sequencer's tick
  return sc::make_bins(s.bin_input(), cfg);
}

void bin_run(Store& store, std::int64_t run_id, double bin_s) {
  for (const auto& slot : store.run_slots(run_id)) {
    const auto bins = bin_samples(store.samples(run_id, slot.serial, true), bin_s);
    store.replace_bins(run_id, slot.serial, bins, slot.earth_rate_dph);
  }
}

SerialFit fit_serial(Store& store, const std::string& serial, std::vector<std::int64_t> runs,
                     const sc::ModelSpec& spec, std::vector<std::string> warnings) {
  if (runs.empty()) runs = store.runs_of_serial(serial);
  // A run named twice is one run: its bins counted twice would halve the variances.
  std::sort(runs.begin(), runs.end());
  runs.erase(std::unique(runs.begin(), runs.end()), runs.end());
  if (runs.empty())
    throw InputError(fmt::format("{}: no run recorded serial '{}'", store.db().path(), serial));
  SerialFit out;
  out.serial = serial;
  out.runs = runs;
  const FitBins bins = fit_bins(store, serial, runs);
  const sc::ModelData& data = bins.data;
  try {
    out.fit = sc::fit_model(data.view(), spec);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: serial '{}', runs {}: {}", store.db().path(), serial,
                                 fmt::join(runs, ","), e.what()));
  }
  out.eval = sc::evaluate(data.bias_dph, sc::compensate(out.fit, data.view()));
  for (const auto id : runs) {
    const auto run = store.find_run(id);
    if (run && run->state == RunState::incomplete)
      warnings.push_back(
          fmt::format("run {} ended incomplete: its record window lost more "
                      "than the configured share of ticks (see its events)",
                      id));
  }
  out.fit.warnings.insert(out.fit.warnings.end(), warnings.begin(), warnings.end());
  out.fit_id = store.save_fit(serial, runs, out.fit, out.eval, bins.span);
  return out;
}

}  // namespace station
