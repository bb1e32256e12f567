// Fits judged against their part: the ADEV floor of the compensated 1 Hz record, the verdict,
// both stored with the fit; and `fit --all`, every serial in one transaction.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "station/parts/part_file.hpp"
#include "station/parts/verdict.hpp"
#include "station/store/calibration.hpp"

namespace station {

/// A stored fit with its verdict (empty: judged against no part).
struct JudgedFit {
  SerialFit fit;
  std::optional<Verdict> verdict;
  std::optional<double> adev_floor_dph;
};

/// Where a fit's limits come from.
struct PartChoice {
  const PartFile* file = nullptr;  ///< --parts FILE: limits by part number (else the run's)
  std::string part_number;         ///< --part PN: the part (else the one the run's slot named)
};

/// The limits for a fit of `serial` over `runs`: the part is `choice.part_number`, or the one its
/// slot named in the newest of the runs; the limits come from `choice.file`, or else the
/// snapshot stored with that run. Empty when no part applies. Throws InputError naming the
/// part file when it lacks the part, or when --part is given without a file.
std::optional<PartLimits> limits_for(Store& store, const std::string& serial,
                                     const std::vector<std::int64_t>& runs,
                                     const PartChoice& choice);

/// The model a fit judged against `limits` uses (one rule for fit, fit --all and run): `given`,
/// whose terms give way to the part's model when the part file fixes one and the terms were
/// not given explicitly (`terms_given`), with the part's noise as the prior on the error model.
compensation::ModelSpec part_model_spec(compensation::ModelSpec given,
                                        const std::optional<PartLimits>& limits, bool terms_given);

/// fit_serial under part_model_spec, and, when the part's model was taken, that choice stored
/// with the fit (migration 9): how fit, fit --all and run fit a gyro of a part.
SerialFit fit_serial_for_part(Store& store, const std::string& serial,
                              const std::vector<std::int64_t>& runs,
                              const compensation::ModelSpec& given,
                              const std::optional<PartLimits>& limits, bool terms_given,
                              std::vector<std::string> warnings = {});

/// The compensated 1 Hz record of `serial` in `run_id`: rate - Earth rate - model, over the
/// samples that went into bins (gaps closed up). Empty when the model has a term the 1 Hz record
/// does not carry (dTdt, channel).
std::vector<double> compensated_record_dph(Store& store, std::int64_t run_id,
                                           const std::string& serial,
                                           const compensation::FitResult& fit);

/// The highest ADEV floor (compensation/adev_floor.hpp) over the runs of `fit`, deg/h: the worst
/// run decides. Empty when no run's record is long enough.
std::optional<double> fit_adev_floor_dph(Store& store, const SerialFit& fit);

/// Judges a stored fit against `limits` and stores the verdict (with the ADEV floor, computed
/// only when the part limits it: it reads every 1 Hz sample). No limits: nothing is stored.
JudgedFit judge_and_store(Store& store, SerialFit fit, const std::optional<PartLimits>& limits);

/// The verdict stored with fit `fit_id`; empty for a fit judged against no part.
std::optional<Verdict> stored_verdict(Store& store, std::int64_t fit_id);

/// What `fit --all` did.
struct FitAllResult {
  std::vector<JudgedFit> fits;
  std::vector<std::string> skipped;  ///< "SERIAL: why" for serials with nothing to fit
};

/// Fits and judges every serial of run `run_id` over that run (no run: every serial of the
/// database over all its runs) in one transaction. A serial with nothing to fit is skipped and
/// listed; a part-file error throws and rolls everything back.
/// `spec` goes through part_model_spec per serial (`terms_given`: the terms were explicit).
FitAllResult fit_all(Store& store, std::optional<std::int64_t> run_id,
                     const compensation::ModelSpec& spec, const PartChoice& choice,
                     bool terms_given = false);

}  // namespace station
