// What the report shows, read from the store: the run record, its events and, per serial, the
// fit of the run and the figures drawn from its samples and bins. Opens nothing itself.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compensation/binning.hpp"
#include "station/release/releases.hpp"
#include "station/release/verification.hpp"
#include "station/report/report_acceptance.hpp"
#include "station/report/report_allan.hpp"
#include "station/report/report_data.hpp"
#include "station/report/report_model.hpp"
#include "station/store/store.hpp"

namespace station::report {

/// What a stored fit carries beyond coefficients and their (honest) standard errors.
struct FitExtras {
  std::optional<std::vector<double>> std_errors_ols;  ///< plain OLS errors, per coefficient
  std::optional<nlohmann::json> verdict;  ///< {"pass": bool, "failed": [{limit, value, bound}]}
};

/// The one place that reads a fit's OLS errors and verdict for the report (`store` for the
/// verdict columns, which are not part of FitRecord). A fit stored before migration 4 has no OLS
/// errors ("-"), one judged against no part no verdict ("no verdict").
FitExtras fit_extras(Store& store, const FitRecord& rec);

/// One serial of the run.
struct SerialReport {
  RunSlot slot;
  /// The run's own fit (store/run_fits.hpp: the first fitted on this run alone); empty: none.
  /// A later fit or release never changes it: those are `other_fits` and dated notes.
  std::optional<FitRecord> fit;
  FitExtras extras;
  AllanCurves allan;                             ///< for the noise terms
  std::vector<Figure> figures;                   ///< 2a, 2b, 3, 4, 5a, 5b (empty without a fit)
  std::optional<ReleaseRow> fit_release;         ///< the newest release of this run's fit
  std::optional<ReleaseRow> current_release;     ///< the serial's released calibration (any fit)
  std::optional<FitRecord> current_release_fit;  ///< its fit (for its model), when not `fit`
  std::vector<OtherFit>
      other_fits;  ///< every other fit that used this run (later ones), oldest first
  /// Verifications stored on this run for this serial, with their per-bin series, and Fig. 6
  /// of each (same order).
  std::vector<VerificationResult> verifications;
  std::vector<Figure> verification_figures;
};

/// One run and its serials.
struct RunReport {
  RunRecord run;
  std::string config_sha256;                ///< SHA-256 of the stored configuration text, hex
  double bin_s = compensation::kPaperBinS;  ///< the run's bin width (run_bin_s)
  std::vector<EventRow> events;
  std::vector<SerialReport> serials;
  /// Each serial's acceptance figures (issue 36); empty when the protocol has no acceptance step.
  std::vector<SerialAcceptanceReport> acceptance;
};

/// Reads run `run_id` and prepares every figure. Throws InputError naming the database when the
/// run does not exist, or none of its serials has a fit and it has no acceptance step.
RunReport load_report(Store& store, std::int64_t run_id);

/// SHA-256 of `text` as 64 lowercase hex digits (FIPS 180-4, through OpenSSL).
std::string sha256_hex(const std::string& text);

}  // namespace station::report
