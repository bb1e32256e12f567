// Acceptance-test physics of the simulated RLG: scale factor, Earth-rate projection, warm-up.
#include "sim_devices/gyro_acceptance.hpp"

#include <cmath>
#include <random>

namespace station::sim {

namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

// The mean of cos(theta - ref) while theta goes linearly from `from_deg` to `to_deg`:
// (sin(to - ref) - sin(from - ref)) / (to - from), the integral of cos over the span.
double mean_cos(double from_deg, double to_deg, double ref_deg) {
  const double span_deg = to_deg - from_deg;
  if (std::fabs(span_deg) < 1e-6)
    return std::cos((0.5 * (from_deg + to_deg) - ref_deg) * kRadPerDeg);
  return (std::sin((to_deg - ref_deg) * kRadPerDeg) - std::sin((from_deg - ref_deg) * kRadPerDeg)) /
         (span_deg * kRadPerDeg);
}

}  // namespace

double scale_factor_error_ppm(const AcceptanceTruth& a, double input_rate_dps, double dt_c) {
  double ppm = a.sf_error_ppm + a.sf_tc_ppm_per_c * dt_c;
  if (a.nonlinearity_ppm != 0 && a.full_scale_dps > 0) {
    // Deviation N*P3(x) ppm of full scale, P3(x) = (5x^3 - 3x)/2, as a part of the rate x:
    // N*(5x^2 - 3)/2 ppm of the rate (AcceptanceTruth).
    const double x = input_rate_dps / a.full_scale_dps;
    ppm += a.nonlinearity_ppm * (5.0 * x * x - 3.0) / 2.0;
  }
  // IEEE 647 asymmetry: SF(+) - SF(-) = asymmetry, split evenly about the mean scale factor.
  if (input_rate_dps > 0) ppm += 0.5 * a.asymmetry_ppm;
  if (input_rate_dps < 0) ppm -= 0.5 * a.asymmetry_ppm;
  return ppm;
}

double table_coupling(const AcceptanceTruth& a) {
  // The input axis's component along up: a tilt d from up keeps cos(d); an axis raised d out of
  // the horizontal plane has sin(d).
  return a.input_axis == InputAxis::vertical ? std::cos(a.misalignment_rad)
                                             : std::sin(a.misalignment_rad);
}

double earth_rate_along_input_dph(const AcceptanceTruth& a, double up_dph, double north_dph,
                                  double from_deg, double to_deg) {
  // Earth rate in ENU (0, W cos(lat), W sin(lat)) (Titterton & Weston, eq. 3.41) dotted with the
  // input axis as the table carries it round.
  const double d = a.misalignment_rad;
  if (a.input_axis == InputAxis::vertical)
    return up_dph * std::cos(d) +
           north_dph * std::sin(d) * mean_cos(from_deg, to_deg, a.misalignment_azimuth_deg);
  return north_dph * std::cos(d) * mean_cos(from_deg, to_deg, a.north_at_table_deg) +
         up_dph * std::sin(d);
}

double warmup_mean_dph(const AcceptanceTruth& a, double from_s, double to_s) {
  if (a.warmup_amplitude_dph == 0 || a.warmup_tau_s <= 0) return 0.0;
  const double tau = a.warmup_tau_s;
  if (to_s - from_s < 1e-9) return a.warmup_amplitude_dph * std::exp(-from_s / tau);
  // The integral of A exp(-t/tau) over the span, divided by the span.
  return a.warmup_amplitude_dph * tau * (std::exp(-from_s / tau) - std::exp(-to_s / tau)) /
         (to_s - from_s);
}

AcceptanceTruth mounted_horizontal(AcceptanceTruth a, double nominal_heading_deg) {
  const double m = a.misalignment_rad, az = a.misalignment_azimuth_deg * kRadPerDeg;
  a.input_axis = InputAxis::horizontal;
  a.nominal_heading_deg = nominal_heading_deg;
  a.north_at_table_deg = nominal_heading_deg + m * std::cos(az) / kRadPerDeg;
  a.misalignment_rad = m * std::sin(az);  // the elevation (AcceptanceTruth)
  return a;
}

double heading_error_rad(const AcceptanceTruth& a) {
  if (a.input_axis != InputAxis::horizontal) return 0.0;
  return std::remainder(a.north_at_table_deg - a.nominal_heading_deg, 360.0) * kRadPerDeg;
}

AcceptanceTruth sim_acceptance_truth(std::uint64_t seed, int index) {
  // A stream of its own (sim_coefficients uses seed*1000003 + index): the thermal truth stays.
  std::mt19937_64 rng(seed * 2000029u + static_cast<std::uint64_t>(index) + 0x36u);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto sign = [&] { return u(rng) < 0.5 ? -1.0 : 1.0; };
  AcceptanceTruth a;
  a.sf_error_ppm = sign() * (10.0 + 50.0 * u(rng));
  a.sf_tc_ppm_per_c = sign() * (1.0 + 4.0 * u(rng));
  a.nonlinearity_ppm = sign() * (10.0 + 40.0 * u(rng));
  a.asymmetry_ppm = sign() * (10.0 + 20.0 * u(rng));
  a.full_scale_dps = 300.0;
  a.turn_on_sigma_dph = 0.004 + 0.002 * u(rng);
  a.warmup_amplitude_dph = sign() * 0.02 * (0.8 + 0.4 * u(rng));
  a.warmup_tau_s = 300.0 * (0.8 + 0.4 * u(rng));
  a.misalignment_rad = 0.5e-3 + 1.5e-3 * u(rng);
  a.misalignment_azimuth_deg = 360.0 * u(rng);
  a.input_axis = InputAxis::vertical;
  return a;
}

}  // namespace station::sim
