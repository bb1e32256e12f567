// A fit's verdict against its part's limits: pass, or each limit that failed with the value and
// the bound. A pure function of the fit, its evaluation and the ADEV floor (no I/O).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compensation/fit.hpp"
#include "station/parts/part_file.hpp"

namespace station {

/// One failed limit. `limit` is the part-file key ("k1_dph_per_c.max", "max_std_ratio", ...);
/// `value` is empty when the fit cannot show it (no k0 term, no 1 Hz record, undefined ratio):
/// a limit that cannot be shown to hold fails.
struct LimitFailure {
  std::string limit;
  std::optional<double> value;
  double bound = 0;
};

/// The verdict on one fit.
struct Verdict {
  std::string part_number;
  bool pass = true;
  std::vector<LimitFailure> failed;
  int checked = 0;  ///< limits the part sets (each end of a range counts once)
  /// What the fit's errors assumed about a rate random walk (walk_text of fit_json.hpp): the
  /// part's noise, or the largest walk the bins could not exclude. Empty in older verdicts.
  std::string context;
};

/// What a verdict looks at besides the coefficients.
struct VerdictInputs {
  const compensation::FitResult& fit;
  const compensation::Evaluation& eval;
  std::optional<double> adev_floor_dph;  ///< ADEV floor of the compensated 1 Hz record
};

/// Checks every limit `limits` sets. Pure.
Verdict judge_fit(const PartLimits& limits, const VerdictInputs& in);

/// What a verification on an independent run shows (station/release/verification.hpp).
struct VerificationFigures {
  double std_after_dph = 0;
  std::optional<double> std_ratio;  ///< empty when undefined
};

/// Checks the verification limits (max_verify_std_dph, max_verify_ratio) only; empty when the
/// part sets neither. Pure.
std::optional<Verdict> judge_verification(const PartLimits& limits, const VerificationFigures& in);

/// {"pass": bool, "failed": [{"limit", "value", "bound"}], "part": number, "checked": n,
/// "context": text}.
nlohmann::json verdict_json(const Verdict& v);
/// The inverse of verdict_json; throws std::invalid_argument on a malformed object.
Verdict verdict_from_json(const nlohmann::json& j);
/// For people: "pass (part GX-100, 12 limits)", "FAIL (part GX-100): k1_dph_per_c.max 0.012 >
/// 0.01 (by 0.002); ...", or "no part limits" for none.
std::string verdict_text(const std::optional<Verdict>& v);

}  // namespace station
