// One gyro's calibrations over time: the run-to-run scatter of k1 and k0 against their reported
// uncertainties, and a flag where a calibration moved more than its uncertainties allow (drift,
// or a damaged gyro). Pure: rows in, statistics out.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "station/store/serial_history.hpp"

namespace station {

/// The action limit of the normalized difference (ζ score) between two calibrations:
/// ζ = (k_new − k_prev) / sqrt(u_new² + u_prev²) with standard uncertainties u (the fits' standard
/// errors), and |ζ| > 3 an action signal — ISO 13528:2015 §9.6 (ζ scores) with the action limit
/// of §9.4 (|score| ≥ 3); the same normalized difference as the E_n number of ISO/IEC 17043:2010
/// Annex B, which uses expanded (k = 2) uncertainties and a limit of 1.
inline constexpr double kDriftZetaLimit = 3.0;

/// A calibration: the newest fit over one set of runs with one set of terms (a refit of the same
/// runs is the same calibration, not a new one).
struct Calibration {
  const SerialFitRow* fit = nullptr;
};

/// A calibration that moved too far from the previous one with the same terms.
struct DriftFlag {
  std::int64_t fit_id = 0, previous_fit_id = 0;
  std::string coefficient;  ///< "k1" or "k0"
  double delta = 0;         ///< k_new - k_prev, deg/h/C
  double zeta = 0;          ///< delta / sqrt(se_new^2 + se_prev^2)
};

/// Scatter of one coefficient over the calibrations.
struct CoefficientScatter {
  std::string coefficient;
  int n = 0;                          ///< calibrations with this coefficient and its SE
  double mean = 0;                    ///< plain mean
  std::optional<double> sample_std;   ///< run-to-run std (n - 1), n >= 2
  std::optional<double> rms_se;       ///< RMS of the reported standard errors
  std::optional<double> chi2;         ///< sum ((k_i - weighted mean) / se_i)^2
  std::optional<double> birge_ratio;  ///< sqrt(chi2 / (n - 1)); ~1 when the SEs explain it
};

/// Everything `station history` computes.
struct SerialHistoryStats {
  std::vector<Calibration> calibrations;  ///< in measurement order (newest run of each)
  std::string terms;  ///< the terms most calibrations used: the scatter is over those
  std::vector<CoefficientScatter> scatter;
  std::vector<DriftFlag> flags;
};

/// Normalized difference of two values with standard uncertainties; empty when both are 0.
std::optional<double> zeta_score(double k_new, double se_new, double k_prev, double se_prev);

/// Calibrations, scatter of k1 and k0 and drift flags from a serial's fits (oldest first). The
/// result points into `fits`.
SerialHistoryStats serial_history_stats(const std::vector<SerialFitRow>& fits);

}  // namespace station
