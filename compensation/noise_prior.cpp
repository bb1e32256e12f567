// The part's noise as a prior on the error model (see the header).
#include "compensation/noise_prior.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace station::compensation {
namespace {

/// ((ln x - ln x0) / ln trust)^2: the log-normal's -2 log density, constants dropped.
double log_normal(double x, double x0, double trust) {
  const double d = std::log(x / x0) / std::log(trust);
  return d * d;
}

}  // namespace

std::optional<double> prior_walk_dph_rt_h(const NoisePrior& prior, double span_h) {
  if (!prior.rrw_dph_rt_h && !prior.bias_instability_dph) return std::nullopt;
  const double k = prior.rrw_dph_rt_h.value_or(0.0), b = prior.bias_instability_dph.value_or(0.0);
  const double tau_h = std::max(span_h, 1e-9);
  const double k_b2 = b * b * 6.0 * std::numbers::ln2 / (std::numbers::pi * tau_h);
  return std::sqrt(k * k + k_b2);
}

double noise_prior_penalty(const NoisePrior& prior, double white_sd_dph, double rrw_dph_rt_h,
                           double bin_s, double span_h) {
  double penalty = 0;
  if (prior.arw_deg_rt_h && white_sd_dph > 0)
    penalty +=
        log_normal(white_sd_dph, 60.0 * *prior.arw_deg_rt_h / std::sqrt(bin_s), prior.trust_factor);
  if (const auto walk = prior_walk_dph_rt_h(prior, span_h)) {
    const double k0 = *walk;
    if (k0 == 0) {
      if (rrw_dph_rt_h > 0) return std::numeric_limits<double>::infinity();
    } else {
      const double floor = k0 / std::pow(prior.trust_factor, 3);
      penalty += log_normal(std::max(rrw_dph_rt_h, floor), k0, prior.trust_factor);
    }
  }
  return penalty;
}

}  // namespace station::compensation
