// Diagnostics every fit carries (issue 22): is a term missing, and can the protocol tell the
// terms apart?
//
// Lack of fit (issue 32): each candidate extension of the model (dT^2, dT^3, dT/dt, gradT x dT)
// not already in it is compared with the model by the likelihood ratio of model_choice.hpp,
// both models with their own error model searched afresh: a missing term the base fit's error
// model took for a "drift" (a rate random walk at the edge of its search) must now beat that
// drift on likelihood (under one shared error model, the old Wald test, it never showed). The m
// candidates are tested together at a family-wise level of 1 % by Bonferroni: the ratio's signed
// root z must pass Phi^-1(1 - 0.005 / m). A significant candidate is named in a warning with
// what k1 and k0 become with it. Each candidate's coefficient and Wald standard error under the
// fit's own error model are kept beside the ratio for reference.
//
// Collinearity: the variance inflation factor of each term (fit.cpp, FitResult::vif); above 10 a
// term is poorly determined (Kutner et al., Applied Linear Statistical Models, 5th ed., §10.5).
// When that is k1 against k0, the warning says so in words: the protocol's gradient follows its
// temperature, and runs at two heating rates (ramp_10 with ramp_20) separate them.
#pragma once

#include "compensation/error_model_search.hpp"
#include "compensation/fit.hpp"

namespace station::compensation {

/// The VIF above which a term is reported as poorly determined.
inline constexpr double kVifLimit = 10.0;

/// The candidate terms of the lack-of-fit check not in `spec` whose data `in` has: dT2, dT3,
/// dTdt, gradTdT (dTdt needs bin slopes, gradTdT gradients). The one list `fit --select` tries.
std::vector<Term> candidates_for(const ModelInput& in, const ModelSpec& spec);

/// The bound |z| must pass when `candidates` terms are tested together (family-wise 1 %).
double candidate_z_critical(std::size_t candidates);

/// Fills fit.candidates, fit.candidate_z_critical and adds the warnings. Candidates whose data
/// are missing (dT/dt of a 1 Hz record) or whose extended fit is impossible are skipped.
/// `lack_of_fit`: the fit's lack_of_fit_problem (model_choice.hpp) with candidates_for(in,
/// fit.spec), on which the fit's error model was estimated (its coarse grid is reused).
void diagnose_fit(const ModelInput& in, FitResult& fit, model_search::Problem& lack_of_fit);

}  // namespace station::compensation
