// Building a coefficient block from a stored fit, its runs' 1 Hz record and its release.
#include "station/release/coefficient_block.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "compensation/scale_factor.hpp"
#include "station/common/text_rule.hpp"
#include "station/parts/deliverable_terms.hpp"
#include "station/store/calibration.hpp"
#include "station/store/fit_model_choice.hpp"
#include "station/store/fit_verdicts.hpp"

// One bound for a usable scale factor, in the station and in the shipped header.
static_assert(GYRO_TC_MAX_SF_DEVIATION == station::compensation::kMaxScaleFactorDeviation);

namespace station {
namespace {

namespace sc = station::compensation;

/// The bin length every run of the fit used; empty when they differ or none says.
std::optional<double> runs_bin_s(Store& store, const std::vector<std::int64_t>& runs) {
  std::optional<double> bin_s;
  for (const auto id : runs) {
    const auto run = store.find_run(id);
    const auto b = run ? recorded_bin_s(*run) : std::nullopt;
    if (!b || (bin_s && *bin_s != *b)) return std::nullopt;
    bin_s = b;
  }
  return bin_s;
}

/// The span of a fit stored before migration 8: from the 1 Hz samples of its complete bins, as
/// make_bins finds it for a fit stored since (the export round-trip test holds the two equal).
FitSpan span_from_samples(Store& store, const FitRecord& fit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  double t_lo = inf, t_hi = -inf, g_lo = inf, g_hi = -inf;
  for (const auto run : fit.runs) {
    const sc::ModelData d = fitted_record_model_data(store, run, fit.serial);
    for (std::size_t i = 0; i < d.temp_c.size(); ++i) {
      t_lo = std::min(t_lo, d.temp_c[i]);
      t_hi = std::max(t_hi, d.temp_c[i]);
      g_lo = std::min(g_lo, d.grad_c[i]);
      g_hi = std::max(g_hi, d.grad_c[i]);
    }
  }
  if (t_lo > t_hi)
    throw InputError(
        fmt::format("{}: fit {}: its runs {} hold no 1 Hz sample of {} in a complete "
                    "bin",
                    store.db().path(), fit.id, fmt::join(fit.runs, ","), fit.serial));
  return FitSpan{t_lo, t_hi, g_lo, g_hi};
}

void set_spans(Store& store, const FitRecord& fit, CoefficientBlock& b) {
  const FitSpan s = fit.span ? *fit.span : span_from_samples(store, fit);
  b.t_min_c = s.temp_min_c;
  b.t_max_c = s.temp_max_c;
  b.grad_min_c = s.grad_min_c;
  b.grad_max_c = s.grad_max_c;
}

/// A block with a value that is not finite is refused: "inf" in a C header does not compile, and
/// JSON would carry null.
void check_finite(const CoefficientBlock& b) {
  std::vector<double> v{b.t_ref_c, b.t_min_c, b.t_max_c, b.grad_min_c, b.grad_max_c};
  v.insert(v.end(), b.coefficients.begin(), b.coefficients.end());
  v.insert(v.end(), b.std_errors.begin(), b.std_errors.end());
  for (const double x : v)
    if (!std::isfinite(x))
      throw InputError(
          fmt::format("fit {} of '{}': a coefficient, error or span is not finite: "
                      "nothing to deliver",
                      b.fit_id, b.serial));
}

/// A scale-factor model the C function could not apply (a value not finite, K(T) not positive
/// over its span: gyro_tc_scale_factor_ok) is not attached, and the block says why: the bias
/// model still travels.
void drop_unusable_scale_factor(CoefficientBlock& b) {
  const auto& m = b.scale_factor.model;
  if (!m) return;
  const double v[] = {m->k0_pulse_per_arcsec,
                      m->k0_se_pulse_per_arcsec,
                      m->tc_ppm_per_c,
                      m->tc_se_ppm_per_c.value_or(0.0),
                      m->t_ref_c,
                      m->t_min_c,
                      m->t_max_c,
                      m->pulse_weight_arcsec,
                      m->earth_rate_dph};
  const bool finite =
      std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); });
  const gyro_tc_block c = b.c_block();
  if (finite && gyro_tc_scale_factor_ok(&c) != 0) return;
  b.scale_factor = {
      std::nullopt,
      fmt::format("not attached: the scale factor of run {} ({}) is {}", fmt::join(m->runs, ","),
                  b.scale_factor.note, finite ? "not positive over its span" : "not finite")};
}

}  // namespace

std::optional<std::string> undeliverable_term(const sc::FitResult& fit) {
  return undeliverable_terms(fit.spec.terms);
}

double CoefficientBlock::coefficient_or_zero(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return coefficients[i];
  return 0.0;
}

gyro_tc_block CoefficientBlock::c_block() const {
  gyro_tc_block c{};
  c.serial = serial.c_str();
  c.part_number = part_number.c_str();
  c.fit_id = fit_id;
  c.released = release ? 1 : 0;
  c.t_ref_c = t_ref_c;
  c.t_min_c = t_min_c;
  c.t_max_c = t_max_c;
  c.grad_min_c = grad_min_c;
  c.grad_max_c = grad_max_c;
  c.b0_dph = coefficient_or_zero("B0");
  for (int i = 0; i < 4; ++i) c.k_dph[i] = coefficient_or_zero(fmt::format("k{}", i + 1));
  c.k0_dph_per_c = coefficient_or_zero("k0");
  c.crc32 = crc32;
  if (const auto& m = scale_factor.model) {
    c.sf_measured = 1;
    c.sf_k0_pulse_per_arcsec = m->k0_pulse_per_arcsec;
    c.sf_tc_ppm_per_c = m->tc_ppm_per_c;
    c.sf_t_ref_c = m->t_ref_c;
    c.sf_t_min_c = m->t_min_c;
    c.sf_t_max_c = m->t_max_c;
    c.pulse_weight_arcsec = m->pulse_weight_arcsec;
    c.earth_rate_dph = m->earth_rate_dph;
  }
  return c;
}

void seal_block(CoefficientBlock& b) {
  // gyro_tc.h holds C strings: a NUL would end the serial the checksum covers ("GX\0-1" read
  // as "GX") while the JSON and CSV carry the whole text.
  for (const std::string* s : {&b.serial, &b.part_number})
    if (s->find('\0') != std::string::npos)
      throw InputError(
          fmt::format("fit {}: serial or part number '{}' holds a NUL: a C string "
                      "cannot carry it, nothing to deliver",
                      b.fit_id, InputError::one_line(*s)));
  const gyro_tc_block c = b.c_block();
  std::string text(GYRO_TC_CANONICAL_MAX, '\0');
  const int n = gyro_tc_canonical(&c, text.data(), text.size());
  if (n < 0)
    throw InputError(fmt::format(
        "fit {} of '{}': the block's canonical text would exceed {} bytes (serial or part "
        "number too long): a consumer could never verify it",
        b.fit_id, b.serial.substr(0, 40), GYRO_TC_CANONICAL_MAX - 1));
  text.resize(static_cast<std::size_t>(n));
  b.canonical = text;
  b.crc32 = gyro_tc_crc32(text.data(), text.size());
}

namespace {

/// A released block whose serial or part number holds ';' or '%' (text the rule of issue 34
/// refuses, so an older station stored it): it was delivered with gyro_tc/2's checksum, which
/// the release did not store, and today's gyro_tc_canonical() escapes those characters
/// (gyro_tc/3). No checksum verifies under both headers: refused rather than re-checksummed.
void refuse_legacy_released_text(const CoefficientBlock& b) {
  if (!b.release) return;
  for (const std::string* s : {&b.serial, &b.part_number})
    if (s->find_first_of(";%") != std::string::npos)
      throw ReleaseRefused(fmt::format(
          "fit {} of serial '{}' is released and its {} '{}' holds ';' or '%' (stored by a "
          "station before the text rule): its release went out with a gyro_tc/2 checksum the "
          "station did not keep, and gyro_tc.h now checksums such text as gyro_tc/3, so a "
          "re-export could not verify on the firmware that holds the old header; nothing "
          "exported (deliver the shipped block, or rename the gyro and release a new fit)",
          b.fit_id, ascii_escaped(b.serial), s == &b.serial ? "serial" : "part number",
          ascii_escaped(*s)));
}

}  // namespace

CoefficientBlock make_block(Store& store, const FitRecord& fit,
                            const std::optional<ReleaseRow>& release) {
  if (const auto bad = undeliverable_term(fit.fit))
    throw ReleaseRefused(fmt::format("fit {} of {}: {}", fit.id, fit.serial, *bad));
  CoefficientBlock b;
  b.serial = fit.serial;
  const StoredVerdict v = load_fit_verdict(store, fit.id);
  b.part_number = v.part_number.value_or("");
  b.verdict_json = v.verdict_json;
  if (const auto choice = load_fit_model_choice(store, fit.id))
    b.model_choice_json = choice->dump();
  b.fit_id = fit.id;
  b.fit_created_utc = fit.created_utc;
  b.terms = fit.terms;
  b.runs = fit.runs;
  b.names = fit.fit.names;
  b.coefficients = fit.fit.coefficients;
  b.std_errors = fit.fit.std_errors;
  b.t_ref_c = fit.fit.spec.ref_temp_c;
  set_spans(store, fit, b);
  b.bin_s = runs_bin_s(store, fit.runs);
  b.std_ratio = fit.eval.std_ratio;
  b.std_after_dph = fit.eval.std_after_dph;
  b.scale_factor = find_scale_factor(store, fit);
  drop_unusable_scale_factor(b);
  b.release = release;
  b.software_version = STATION_VERSION;
  check_finite(b);
  refuse_legacy_released_text(b);
  seal_block(b);
  return b;
}

}  // namespace station
