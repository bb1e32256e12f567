// Forward selection of the model's terms (see the header).
#include "compensation/model_selection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "compensation/cross_validation.hpp"
#include "compensation/fit_diagnostics.hpp"
#include "compensation/model_choice.hpp"

namespace station::compensation {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

/// The candidates not in the model whose data the bins have, among `allowed` (empty: all).
std::vector<Term> allowed_candidates(const ModelInput& in, const ModelSpec& s,
                                     std::span<const Term> allowed) {
  std::vector<Term> out;
  for (const Term t : candidates_for(in, s))
    if (allowed.empty() || std::find(allowed.begin(), allowed.end(), t) != allowed.end())
      out.push_back(t);
  return out;
}

ModelSpec with(const ModelSpec& s, Term t) {
  ModelSpec out = s;
  out.terms.push_back(t);
  return out;
}

/// The one-standard-error rule on paired folds (Hastie, Tibshirani & Friedman §7.10.1, here for
/// one more term): the held-out mean squared error of each run without the term minus with it,
/// d_r; the term helps when mean(d) exceeds its standard error sd(d) / sqrt(R). With two runs
/// that is: it lowers the prediction error on both.
double help_beyond_one_se(const CrossValidation& without, const CrossValidation& with_term) {
  std::vector<double> d;
  for (std::size_t r = 0; r < without.runs.size() && r < with_term.runs.size(); ++r)
    d.push_back(std::pow(without.runs[r].rms_dph, 2) - std::pow(with_term.runs[r].rms_dph, 2));
  if (d.size() < 2) return 0;
  double mean = 0;
  for (const double v : d) mean += v / static_cast<double>(d.size());
  return mean - sample_std(d) / std::sqrt(static_cast<double>(d.size()));
}

/// One forward step: every allowed candidate tried, its likelihood ratio taken. With `current`
/// (two or more runs), of the candidates that help beyond one standard error and whose ratio
/// passes the bound, the one with the lowest pooled held-out RMS (`current` becomes its
/// cross-validation); without, the one with the largest ratio beyond the bound.
std::optional<Term> step_forward(const ModelInput& in, ModelSelection& sel, int step,
                                 std::span<const Term> allowed, CrossValidation* current) {
  const std::vector<Term> cands = allowed_candidates(in, sel.chosen, allowed);
  if (cands.empty()) return std::nullopt;
  const double bound = std::pow(candidate_z_critical(cands.size()), 2);
  const std::vector<double> lr = extension_likelihood_ratios(in, sel.chosen, cands, bound);
  std::optional<Term> best;
  double best_score = INFINITY;  // held-out RMS, or minus the ratio
  std::optional<CrossValidation> best_cv;
  for (std::size_t k = 0; k < cands.size(); ++k) {
    TriedModel m;
    m.spec = with(sel.chosen, cands[k]);
    m.step = step;
    m.added = term_option_name(cands[k]);
    m.likelihood_ratio = lr[k];
    const bool passes = lr[k] > bound;
    if (current == nullptr) {
      if (passes && -lr[k] < best_score) best_score = -lr[k], best = cands[k];
    } else {
      try {
        CrossValidation cv = leave_one_run_out(in, m.spec);
        m.held_out_rms_dph = cv.pooled_rms_dph;
        if (passes && help_beyond_one_se(*current, cv) > 0 && cv.pooled_rms_dph < best_score)
          best_score = cv.pooled_rms_dph, best = cands[k], best_cv = std::move(cv);
      } catch (const std::exception& e) {
        m.not_fitted = e.what();
      }
    }
    sel.tried.push_back(std::move(m));
  }
  if (best_cv) *current = std::move(*best_cv);
  return best;
}

}  // namespace

ModelSelection select_model(const ModelInput& in, const ModelSpec& base,
                            std::span<const Term> allowed) {
  ModelSelection sel;
  sel.chosen = base;
  const std::set<int> runs(in.segment.begin(), in.segment.end());
  CrossValidation current;
  std::string no_cv;  // why leave-one-run-out could not decide
  sel.tried.emplace_back().spec = base;
  if (runs.size() >= 2) {
    try {
      current = leave_one_run_out(in, base);
      sel.tried.back().held_out_rms_dph = current.pooled_rms_dph;
    } catch (const std::exception& e) {
      no_cv = std::string(" (leave-one-run-out not possible: ") + e.what() + ")";
    }
  }
  const bool cv = runs.size() >= 2 && no_cv.empty();
  sel.method = cv ? "leave-one-run-out" : "likelihood ratio";
  if (!cv) (void)fit_model(in, base);  // the base must fit: its errors are what the caller reads
  for (int step = 1;; ++step) {
    const auto t = step_forward(in, sel, step, allowed, cv ? &current : nullptr);
    if (!t) break;
    sel.chosen = with(sel.chosen, *t);
  }
  for (auto& m : sel.tried) m.chosen = m.spec.terms == sel.chosen.terms && !m.not_fitted;
  sel.reason =
      cv ? "held-out RMS " + num(current.pooled_rms_dph * 1e3) + " mdeg/h over " +
               std::to_string(runs.size()) +
               " runs, each left out in turn; a term added only where it lowered the held-out "
               "error by more than its standard error across the runs and its likelihood ratio "
               "passed the 1 % family-wise bound"
         : "each term added only while its likelihood ratio (each model with its own error "
           "model) passed the 1 % family-wise bound over the candidates left" +
               no_cv;
  sel.reason = model_text(sel.chosen) + ": " + sel.reason;
  return sel;
}

}  // namespace station::compensation
