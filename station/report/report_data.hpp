// The report's figures as data: the paper's Figs. 2a-5b (Zhou et al. 2013) computed from a
// run's samples, bins and fit. Pure functions of what was stored; no I/O (report_load reads the
// store, report_html draws).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "compensation/fit.hpp"
#include "station/store/store.hpp"

namespace station::report {

/// One series of a chart: points (x[i], y[i]); y_low/y_high (same length, or empty) are its
/// confidence interval. A NaN y is no point.
struct Series {
  std::string label;
  std::vector<double> x, y, y_low, y_high;
  bool line = false;      ///< drawn as a line (else points only)
  bool second_y = false;  ///< on the right-hand axis
  /// y_low/y_high drawn as each point's error bar (whiskers), not as a band between points.
  bool whiskers = false;
  bool large_points = false;  ///< points drawn larger (a few measured points on a curve)
};

/// One figure: its id ("2a".."5b"), axes and series; `note` is shown under it (e.g. why it is
/// empty).
struct Figure {
  std::string id, title, x_label, y_label, y2_label, note;
  std::vector<Series> series;
  bool log_axes = false;  ///< both axes logarithmic (Allan deviation)
  /// Points drawn: finite y values over every series.
  std::size_t points() const;
};

/// A figure with its titles and no series yet.
Figure make_figure(std::string id, std::string title, std::string x_label, std::string y_label,
                   std::string y2_label = {});

/// A bin of the whole run (record window or not) at the run's bin width, for Figs. 2a/2b.
struct RunBin {
  double t_mid_s = 0;       ///< bin centre, s since the run started
  double bias_dph = 0;      ///< bin mean rate minus Earth rate, deg/h
  double temp_c = 0;        ///< gyro temperature (sensor A), deg C
  double air_c = 0;         ///< chamber air, deg C (NaN when the chamber never answered)
  double dtdt_c_per_h = 0;  ///< least-squares slope of temp_c over the bin, deg C/h
};

/// Bins every usable sample of the run at bin_s (not only the record window: the return to
/// start is the cooling branch of Fig. 2b). Samples without rate or temperatures or flagged
/// kUnfitFlags are left out, as bin_run does; incomplete bins (< 90 % full) are dropped.
std::vector<RunBin> whole_run_bins(const std::vector<SampleRow>& rows, double bin_s,
                                   double earth_rate_dph);

/// Fig. 2a: bias and the chamber / gyro temperatures (right axis) against time in hours; the
/// title names `bin_s`, the run's bin width (store/calibration.hpp run_bin_s).
Figure figure_2a(const std::vector<RunBin>& bins, double bin_s);

/// Temperature slope beyond which a bin counts as heating or cooling, deg C/h.
inline constexpr double kBranchSlopeCPerH = 1.0;

/// Fig. 2b: bias against temperature, heating (dT/dt > kBranchSlopeCPerH), cooling (<
/// -kBranchSlopeCPerH) and steady bins as three series: the hysteresis between the branches.
Figure figure_2b(const std::vector<RunBin>& bins);

/// One ramp run of the serial (protocol ramp_00/ramp_10/ramp_20) and its complete bins.
struct RampRun {
  std::string protocol;
  std::int64_t run_id = 0;
  compensation::ModelData data;
};

/// Fig. 3: bias against temperature per ramp run; with none, no points and a note saying so.
Figure figure_3(const std::vector<RampRun>& ramps);

/// The model with only the named coefficients kept (the others zero), evaluated on `data`:
/// e.g. {"k1"} is k1 dT, {"B0","k1",...} the model without its gradient term.
std::vector<double> model_part(const compensation::FitResult& fit,
                               const compensation::ModelInput& data,
                               const std::vector<std::string>& keep);

/// Names of the temperature terms of a fit (k1..k4): "removing k1 dT" removes all of them.
std::vector<std::string> temperature_terms(const compensation::FitResult& fit);

/// Fig. 4: bias minus the temperature terms (k_i dT^i) against the gradient, with the fitted
/// line B0 + k0 gradT (paper eq. (4)); a fit without a gradient term gets a note, no line.
Figure figure_4(const compensation::FitResult& fit, const compensation::ModelData& data);

/// Fig. 5a: bias before compensation, after the temperature terms only (bias - B0 - sum k_i
/// dT^i) and after the whole model (bias - B(x), paper eq. (4)), against temperature.
Figure figure_5a(const compensation::FitResult& fit, const compensation::ModelData& data);
/// Fig. 6 (Fig. 5a's form, for a verification): the bias of a run before and after a
/// calibration fitted on other runs, against temperature, per complete bin.
Figure figure_6(std::int64_t fit_id, const std::vector<double>& temp_c,
                const std::vector<double>& before_dph, const std::vector<double>& after_dph);

}  // namespace station::report
