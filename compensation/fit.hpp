// Thermal bias model of the paper, eq. (3)/(4), generalized, fitted by least squares (QR).
//   B = B0 + sum_i k_i dT^i (i = 1..4) + k0 gradT [+ kr dT/dt] [+ kc channel],  dT = T - T_ref.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "compensation/binning.hpp"
#include "compensation/correlated_errors.hpp"

namespace station::compensation {

/// A regressor of the model besides the constant B0.
/// gradTdT is the gradient times dT (a gradient sensitivity that changes with temperature): a
/// candidate of the lack-of-fit check (fit_diagnostics.hpp) that a user may also fit.
enum class Term { dT, dT2, dT3, dT4, gradT, dTdt, channel, gradTdT };

/// Option name of a term: "dT", "dT2", "dT3", "dT4", "gradT", "dTdt", "channel", "gradTdT".
std::string_view term_option_name(Term t);
/// Coefficient name of a term as the paper writes it: k1..k4, k0 (gradient), kr (rate), kc,
/// kg (gradient x dT).
std::string_view term_coefficient_name(Term t);
/// Unit of a coefficient by name ("B0" -> "deg/h", "k1" -> "deg/h/C", ...); empty when unknown.
std::string_view coefficient_unit(std::string_view coefficient_name);
/// Parses an option name; empty when unknown.
std::optional<Term> term_from_option_name(std::string_view name);
/// Parses a comma-separated list of option names; throws std::invalid_argument naming a bad one.
std::vector<Term> parse_terms(std::string_view list);

/// Which terms, and the reference temperature for dT.
struct ModelSpec {
  ModelSpec() = default;
  ModelSpec(std::vector<Term> t, double ref_c, std::optional<NoisePrior> prior = std::nullopt)
      : terms(std::move(t)), ref_temp_c(ref_c), noise_prior(std::move(prior)) {}

  std::vector<Term> terms{Term::dT, Term::gradT};  ///< the paper's k1 and k0
  double ref_temp_c = 25.0;                        ///< T_ref, deg C
  /// The part's noise, a prior on the error model (noise_prior.hpp); empty: none known.
  std::optional<NoisePrior> noise_prior;
};

/// A model's terms as one word, "B0+dT+gradT".
std::string model_text(const ModelSpec& spec);

/// Per-bin model inputs (all spans the same length; grad/dtdt/channel may be empty if unused).
struct ModelInput {
  std::span<const double> bias_dph;      ///< bin mean rate minus Earth rate, deg/h
  std::span<const double> temp_c;        ///< bin mean temperature, deg C
  std::span<const double> grad_c;        ///< bin mean gradient, deg C
  std::span<const double> dtdt_c_per_h;  ///< bin temperature slope, deg C/h
  std::span<const double> channel;       ///< bin mean of an extra channel
  /// Bin times, s, increasing within a run (empty: equally spaced). They set how strongly the
  /// errors of two bins are correlated (correlated_errors.hpp).
  std::span<const double> t_s;
  /// The run each bin came from (empty: one run); bins of different runs are independent.
  std::span<const int> segment;
};

/// Owning per-bin series built from bins; view() gives the ModelInput.
struct ModelData {
  std::vector<double> bias_dph, temp_c, grad_c, dtdt_c_per_h, channel, t_mid_s;
  std::vector<int> segment;  ///< run index per bin (empty: one run)
  ModelInput view() const {
    return {bias_dph, temp_c, grad_c, dtdt_c_per_h, channel, t_mid_s, segment};
  }
};

/// Complete bins only, each bias the bias_dph() of its mean rate (earth_rate.hpp).
ModelData model_data_from_bins(std::span<const Bin> bins, double earth_rate_dph);

/// A fitted model with its statistics. coefficients[0] is B0; names[i] labels coefficients[i].
struct FitResult {
  ModelSpec spec;
  std::vector<std::string> names;
  std::vector<double> coefficients;  ///< deg/h, deg/h/C^i, deg/h/C, deg/h/(C/h), ...
  /// One standard error per coefficient, honest for correlated bins: the OLS coefficients'
  /// spread under the error model fitted to the bins (white + Gauss-Markov, REML;
  /// correlated_errors.hpp). This is the uncertainty the station reports.
  std::vector<double> std_errors;
  /// The textbook OLS standard errors s^2 (X'X)^-1, which assume independent bins; kept for
  /// comparison (they are optimistic when the bins share bias-instability noise).
  std::vector<double> std_errors_ols;
  ErrorModel error_model;  ///< the error model behind std_errors
  /// Without a prior: each coefficient's standard error under the largest walk the bins do not
  /// exclude (error_model.walk_not_excluded); empty when there is none or a prior was given.
  std::vector<double> std_errors_walk_not_excluded;
  /// Newey-West (HAC) standard errors: honest when the residuals of neighbouring bins are
  /// correlated (bias instability over hours). Bartlett weights up to hac_lag bins.
  std::vector<double> std_errors_hac;
  std::size_t hac_lag = 0;
  std::size_t n_points = 0;           ///< bins used
  std::size_t dof = 0;                ///< n_points - coefficients
  double r2 = 0;                      ///< coefficient of determination
  double residual_rms_dph = 0;        ///< sqrt(RSS / n)
  double condition_number = 0;        ///< 2-norm condition of the column-scaled design matrix
  std::vector<std::string> warnings;  ///< e.g. nearly collinear terms, a missing term
  /// Variance inflation factor of each term (names[1..]), Kutner et al. 2005 §10.5.
  std::vector<double> vif;
  /// The lack-of-fit check (fit_diagnostics.hpp): each candidate term not in the model, tried.
  struct Candidate {
    std::string option;    ///< "dT2", "dT3", "dTdt", "gradTdT"
    double value = 0;      ///< its coefficient in the extended model
    double std_error = 0;  ///< its standard error under this fit's error model (Wald)
    /// The likelihood ratio of the extended model against this one, each with its own error
    /// model (model_choice.hpp): chi^2 with 1 degree of freedom when the term is absent.
    double likelihood_ratio = 0;
    double z = 0;                      ///< its signed root: sign(value) sqrt(likelihood_ratio)
    bool significant = false;          ///< |z| above the Bonferroni bound
    std::vector<double> coefficients;  ///< the extended model's, names then the candidate's
  };
  std::vector<Candidate> candidates;
  double candidate_z_critical = 0;  ///< the bound |z| must pass (family-wise 1 %)
};

/// Least squares through Householder QR of the column-scaled design matrix (not normal
/// equations). Throws DataError (compensation/limits.hpp) on too few points, missing or constant
/// series, a value that is not finite or outside its physical bound (bias within
/// +-kMaxAbsRateDph, temperatures and T_ref within kMinTempC..kMaxTempC, gradients within
/// +-kMaxAbsTempDiffC), linearly dependent terms, or a result that is not finite.
FitResult fit_model(const ModelInput& in, const ModelSpec& spec);

/// The same fit under a given error model (no REML search) and without diagnostics: how the
/// lack-of-fit check fits a model's extensions under that model's own error model.
FitResult fit_model_under(const ModelInput& in, const ModelSpec& spec, const ErrorModel& model);

/// Refuses data the model cannot use: every value finite and within its physical bound, so no
/// entry of the design matrix, and no sum of their squares, can overflow. Throws DataError
/// naming the bin and the term.
void check_model_input(const ModelInput& in, const ModelSpec& spec);

/// The design matrix of `spec` on `in`: a column of ones (B0), then one column per term in the
/// spec's order. Throws DataError when a term has no data for every bin.
Eigen::MatrixXd design_matrix(const ModelInput& in, const ModelSpec& spec);

/// Model value B(x) at each point.
std::vector<double> predict(const FitResult& fit, const ModelInput& in);

/// Compensated bias: bias - B(x) at each point (the residuals for the fitted data).
std::vector<double> compensate(const FitResult& fit, const ModelInput& in);

/// Sample standard deviation with N-1 in the denominator (0 for fewer than 2 values).
double sample_std(std::span<const double> v);

/// Std of the bias before and after compensation, their ratio and 1 - ratio in percent
/// (the paper's figure of merit: ratio 0.13, "87 %"). The ratio is undefined (empty) when the
/// std before is at the rounding level of the data: a constant input has nothing to improve,
/// and a ratio of two rounding errors would invent an improvement.
struct Evaluation {
  double std_before_dph = 0;
  double std_after_dph = 0;
  std::optional<double> std_ratio;        ///< std_after / std_before; empty when undefined
  std::optional<double> improvement_pct;  ///< 100 (1 - std_ratio); empty with it
};

/// Evaluates before/after series of equal meaning (bias and compensated bias). `removed_dph` is
/// a constant the caller subtracted from the measured rates to make `before` (the Earth rate):
/// the rounding level is set by the magnitude of the values before that subtraction.
/// Throws DataError when a value is not finite.
Evaluation evaluate(std::span<const double> before_dph, std::span<const double> after_dph,
                    double removed_dph = 0);

}  // namespace station::compensation
