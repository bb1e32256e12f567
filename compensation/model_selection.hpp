// Which model to deliver (issue 32, `station fit --select`): forward selection from the base
// model over the lack-of-fit candidates (fit_diagnostics.hpp: dT2, dT3, dTdt, gradTdT), one term
// a step, each step adding the candidate that helps most while it helps.
//   - Two or more runs: by leave-one-run-out prediction error (cross_validation.hpp; Hastie,
//     Tibshirani & Friedman, Elements of Statistical Learning, 2nd ed., §7.10): a term is added
//     when it lowers each held-out run's mean squared error by more than one standard error
//     across the runs (with two runs: on both), and the likelihood ratio below, over all the
//     runs, passes its bound. Two or three folds cannot keep chance out on their own: without
//     the ratio's guard 1 in 3 realizations of a model with nothing missing took a term
//     (test ModelSelection); of the candidates passing both, the lowest pooled held-out RMS.
//   - One run: by the likelihood ratio of model_choice.hpp, each model with its own error model:
//     a term is added when its ratio passes the lack-of-fit check's bound over the candidates
//     left (family-wise 1 %), the same rule that warns of a missing term.
// Pure maths: no I/O.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "compensation/fit.hpp"

namespace station::compensation {

/// One model the selection tried.
struct TriedModel {
  ModelSpec spec;
  int step = 0;                            ///< 0: the base; k: the k-th term added
  std::string added;                       ///< the term this model adds to its step's start
  std::optional<double> held_out_rms_dph;  ///< pooled leave-one-run-out RMS (two or more runs)
  std::optional<double> likelihood_ratio;  ///< against its step's start (one run)
  std::optional<std::string> not_fitted;   ///< why it could not be tried
  bool chosen = false;                     ///< the model selected
};

struct ModelSelection {
  std::string method;  ///< "leave-one-run-out" or "likelihood ratio"
  ModelSpec chosen;
  std::vector<TriedModel> tried;
  std::string reason;  ///< one line: why this model
};

/// Forward selection from `base` (see above) over the lack-of-fit candidates that are in
/// `allowed` (empty: all of them; `fit --select` allows the terms a release can carry). Throws
/// DataError when the base model cannot be fitted.
ModelSelection select_model(const ModelInput& in, const ModelSpec& base,
                            std::span<const Term> allowed = {});

}  // namespace station::compensation
