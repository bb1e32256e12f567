// Fig. 5b of the report: Allan deviation of the 1 Hz record before and after compensation
// (IEEE Std 952-1997 Annex C; Zhou et al. 2013, Fig. 5b). Pure; no I/O.
#pragma once

#include <vector>

#include "compensation/allan.hpp"
#include "station/report/report_data.hpp"

namespace station::report {

/// The 1 Hz record of the record window as the Allan curves see it.
struct OneHzRecord {
  std::vector<double> bias_dph;         ///< rate - Earth rate
  std::vector<double> compensated_dph;  ///< bias - B(temp, temp2 - temp) per sample
};

/// The record window's usable samples (as bin_samples takes them): bias and the compensated
/// bias, the model evaluated per sample with its own temperature and gradient; dT/dt, when the
/// model has it, is the slope of the sample's bin (stored bins are the model's inputs).
OneHzRecord one_hz_record(const std::vector<SampleRow>& rows, double earth_rate_dph,
                          const compensation::FitResult& fit, double bin_s);

/// Allan deviation before and after compensation with their noise terms (IEEE 952 Annex C).
struct AllanCurves {
  std::vector<compensation::AdevPoint> before, after;
  compensation::NoiseTerms noise_before, noise_after;
};

/// Overlapping ADEV (octave taus, 68.3 % intervals) of both series of the 1 Hz record; empty
/// curves when fewer than 3 samples.
AllanCurves allan_curves(const OneHzRecord& record);

/// Fig. 5b: the two Allan curves with their confidence intervals, log-log.
Figure figure_5b(const AllanCurves& curves);

}  // namespace station::report
