// `station fleet --propose-noise`: the part's noise ([part."PN".noise], compensation/
// noise_prior.hpp) proposed from the fleet's runs (issue 32, point 3). Pure: the runs' terms in,
// the proposal, its TOML block and its JSON out (fleet_noise.hpp reads the runs).
//
// Per run and serial, the estimate is what the run report's Fig. 5b fits: the IEEE 952 terms N,
// B, K fitted to the overlapping Allan variance of the compensated 1 Hz record (IEEE Std
// 952-1997 Annex C, Table C.2; compensation::fit_noise_terms, its errors from the covariance of
// the overlapping estimates). What the thermal model leaves in the record (a missing term) adds to
// B and K: the proposal is the noise the station's compensation leaves, which is what the fit's
// error model must carry.
// Per part, each term is the median over the usable runs (a term the run's fit dropped counts as
// 0; the term is proposed only where it is above 0 in at least kMinNoiseRuns runs and in most
// of them), and its spread the robust geometric standard deviation between those runs,
//   s = 1.4826 MAD(ln x) (the MAD scaled to sigma for normal ln x; Hampel 1974, Huber &
//   Ronchetti, Robust Statistics, 2nd ed. 2009, §5.1).
// The trust factor is the part file's geometric sd of a part's true term about the value given:
// for a new part about the median of n runs, sqrt(s^2 + (pi / 2) s^2 / n) in ln (the variance of
// the median of n normal values, pi sigma^2 / 2n: Kendall & Stuart, Advanced Theory of Statistics
// vol. 1, §10.10), the largest over the proposed terms, kept in kMinNoiseTrust..kMaxNoiseTrust.
// The spread between runs includes each run's estimation error, so the factor is conservative.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compensation/allan.hpp"
#include "compensation/noise_prior.hpp"

namespace station::fleet {

/// Usable runs a part needs for a proposal, and runs a term must be seen in.
inline constexpr int kMinNoiseRuns = 3;

/// One run of one serial as the fleet holds it, with its estimate or why it has none.
struct RunNoise {
  std::string part, station, serial, run_uuid;
  std::int64_t fit_fleet_id = 0;                  ///< the fit whose model compensated the run
  std::optional<compensation::NoiseTerms> terms;  ///< empty: no usable estimate
  std::string problem;                            ///< why not, when terms is empty
  std::size_t samples = 0;                        ///< 1 Hz samples of the record window used
};

/// One IEEE 952 term pooled over a part's usable runs.
struct PooledTerm {
  std::string key;                  ///< the part-file key: arw_deg_rt_h, ...
  std::string unit;                 ///< deg/sqrt(h), deg/h, deg/h/sqrt(h)
  int runs_with = 0;                ///< runs whose fit kept the term (above 0)
  std::optional<double> median;     ///< over all usable runs, absent = 0; empty: not proposed
  std::optional<double> log_sd;     ///< s = 1.4826 MAD(ln x) over the runs with the term
  std::optional<double> min, max;   ///< over the runs with the term
  std::optional<double> median_se;  ///< the runs' own standard errors, their median
  std::string why_not;              ///< when median is empty
};

/// A part's proposal, or why it has none.
struct NoiseProposal {
  std::string part;
  int runs = 0, usable = 0, stations = 0, serials = 0;  ///< counted over the usable runs
  std::vector<RunNoise> unusable;                       ///< the runs with no estimate
  std::vector<PooledTerm> terms;                        ///< N, B, K in that order
  std::optional<compensation::NoisePrior> prior;        ///< empty: no proposal
  std::string why_none;                                 ///< when prior is empty
};

/// One proposal per part among `runs` (any order), parts in sort order.
std::vector<NoiseProposal> propose_noise(const std::vector<RunNoise>& runs);

/// The ready-to-paste `[part."PN".noise]` block (terms with their units and provenance as TOML
/// comments); a part with no proposal gives comment lines saying why.
std::string noise_toml(const NoiseProposal& p);

/// {"part", "runs", "usable_runs", "stations", "serials", "terms": [{"key", "unit", "value",
/// "runs_with_term", "log_sd", "min", "max", "median_se", "why_not"}], "trust_factor", "toml",
/// "why_none", "unusable": [{"station", "serial", "run_uuid", "fit_fleet_id", "problem"}]}
nlohmann::json noise_proposal_json(const NoiseProposal& p);

}  // namespace station::fleet
