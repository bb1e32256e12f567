// Reading a run for the report: run record, events, per serial the fit, bins and samples.
#include "station/report/report_load.hpp"

#include <fmt/format.h>
#include <openssl/evp.h>

#include <algorithm>
#include <array>
#include <map>

#include "station/common/input_error.hpp"
#include "station/store/calibration.hpp"
#include "station/store/fit_verdicts.hpp"
#include "station/store/run_fits.hpp"

namespace station::report {

namespace {

/// The newest run of each ramp protocol (ramp_00/10/20) that recorded `serial` and has complete
/// bins, in protocol order.
std::vector<RampRun> ramp_runs(Store& store, const std::string& serial) {
  std::map<std::string, std::int64_t> newest;
  for (const auto id : store.runs_of_serial(serial)) {
    const auto run = store.find_run(id);
    if (!run) continue;
    const auto& p = run->protocol_name;
    if (p == "ramp_00" || p == "ramp_10" || p == "ramp_20") newest[p] = std::max(newest[p], id);
  }
  std::vector<RampRun> out;
  for (const auto& [protocol, id] : newest) {
    RampRun r{protocol, id, store.model_data(serial, {id})};
    if (!r.data.bias_dph.empty()) out.push_back(std::move(r));
  }
  return out;
}

/// The serial's verifications on the run, oldest first; a verification identical to an earlier
/// one (the same fit, part, figures and verdict: `verify` called again before it reported the
/// stored one) folded into the newest copy, which names when the first was stored.
std::vector<VerificationResult> distinct_verifications(Store& store, std::int64_t run_id,
                                                       const std::string& serial) {
  std::vector<VerificationResult> out;
  std::vector<std::string> keys;  // verification_json of each as stored (part and verdict in it)
  for (auto& v : verifications_of_run(store, run_id)) {
    if (v.serial != serial) continue;
    std::string key = verification_json(v).dump();
    const auto same = std::find(keys.begin(), keys.end(), key);
    if (same != keys.end()) {
      const auto& first = out[static_cast<std::size_t>(same - keys.begin())];
      v.warnings.push_back(
          fmt::format("the same verification was stored before, on {} "
                      "(verification {}): shown once",
                      first.created_utc, first.id));
      out.erase(out.begin() + (same - keys.begin()));
      keys.erase(same);
    }
    out.push_back(std::move(v));
    keys.push_back(std::move(key));
  }
  return out;
}

/// The verifications stored on run `run_id` for the serial, each recomputed for its series (the
/// stored figures and verdict are kept: they are what was reported when it ran).
void load_verifications(Store& store, std::int64_t run_id, SerialReport& s) {
  for (auto& stored : distinct_verifications(store, run_id, s.slot.serial)) {
    if (const auto fit = store.find_fit(stored.fit_id)) {
      const VerificationResult again = verify_fit(store, *fit, run_id, std::nullopt);
      stored.t_s = again.t_s;
      stored.temp_c = again.temp_c;
      stored.before_dph = again.before_dph;
      stored.after_dph = again.after_dph;
    }
    s.verification_figures.push_back(
        figure_6(stored.fit_id, stored.temp_c, stored.before_dph, stored.after_dph));
    s.verifications.push_back(std::move(stored));
  }
  // One verification is Fig. 6; several are Figs. 6.1, 6.2, ...
  if (s.verification_figures.size() > 1)
    for (std::size_t k = 0; k < s.verification_figures.size(); ++k)
      s.verification_figures[k].id = fmt::format("6.{}", k + 1);
}

SerialReport load_serial(Store& store, const RunReport& rr, const RunSlot& slot) {
  SerialReport s;
  s.slot = slot;
  s.current_release = current_release(store, slot.serial);
  load_verifications(store, rr.run.id, s);
  auto fits = fits_of_run(store, slot.serial, rr.run.id);
  const auto own = own_fit_index(fits, rr.run.id);
  for (std::size_t i = 0; i < fits.size(); ++i)
    if (i != own) s.other_fits.push_back({fits[i], release_of_fit(store, fits[i].id)});
  if (own) s.fit = std::move(fits[*own]);
  if (s.current_release && (!s.fit || s.current_release->fit_id != s.fit->id))
    s.current_release_fit = store.find_fit(s.current_release->fit_id);
  if (!s.fit) return s;
  s.extras = fit_extras(store, *s.fit);
  s.fit_release = release_of_fit(store, s.fit->id);
  const auto samples = store.samples(rr.run.id, slot.serial, false);
  const auto bins = whole_run_bins(samples, rr.bin_s, slot.earth_rate_dph);
  const auto data = store.model_data(slot.serial, s.fit->runs);
  s.allan = allan_curves(one_hz_record(samples, slot.earth_rate_dph, s.fit->fit, rr.bin_s));
  s.figures = {figure_2a(bins, rr.bin_s),
               figure_2b(bins),
               figure_3(ramp_runs(store, slot.serial)),
               figure_4(s.fit->fit, data),
               figure_5a(s.fit->fit, data),
               figure_5b(s.allan)};
  return s;
}

}  // namespace

FitExtras fit_extras(Store& store, const FitRecord& rec) {
  FitExtras e;
  // std_errors is the honest (error-model) uncertainty; the plain OLS figures sit beside it.
  if (rec.fit.std_errors_ols.size() == rec.fit.coefficients.size())
    e.std_errors_ols = rec.fit.std_errors_ols;
  // The verdict stored with the fit (fits.verdict_json, migration 5); none for a fit judged
  // against no part.
  const StoredVerdict stored = load_fit_verdict(store, rec.id);
  if (stored.verdict_json) e.verdict = nlohmann::json::parse(*stored.verdict_json);
  return e;
}

RunReport load_report(Store& store, std::int64_t run_id) {
  const auto run = store.find_run(run_id);
  if (!run) throw InputError(fmt::format("{}: no run {}", store.db().path(), run_id));
  RunReport rr;
  rr.run = *run;
  rr.config_sha256 = sha256_hex(run->config_text);
  rr.bin_s = run_bin_s(*run);
  rr.events = store.event_rows(run_id);
  bool any_fit = false;
  for (const auto& slot : store.run_slots(run_id)) {
    rr.serials.push_back(load_serial(store, rr, slot));
    any_fit = any_fit || rr.serials.back().fit.has_value();
  }
  rr.acceptance = load_acceptance(store, rr.run);
  if (!any_fit && rr.acceptance.empty())
    throw InputError(fmt::format("{}: run {} has no stored fit (run `station fit --all --run {}`)",
                                 store.db().path(), run_id, run_id));
  return rr;
}

std::string sha256_hex(const std::string& text) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned int n = 0;
  if (EVP_Digest(text.data(), text.size(), md.data(), &n, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("SHA-256 failed (OpenSSL EVP_Digest)");
  std::string hex;
  for (unsigned int i = 0; i < n; ++i) hex += fmt::format("{:02x}", md[i]);
  return hex;
}

}  // namespace station::report
