// The report's acceptance pages (issue 36): a page per test kind (scale factor, turn-on,
// positions) with the figures people expect, drawn from station/acceptance's figures. Figures
// are data here (pure); report_acceptance_load reads what the figures' structs do not carry,
// report_acceptance_pages writes the HTML.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "station/acceptance/acceptance_run.hpp"
#include "station/report/report_data.hpp"
#include "station/store/store.hpp"

namespace station::report {

/// One turn-on's bias against the time since its power-up, in acceptance_run's kTurnOnBinS bins.
using WarmupCurve = TurnOnCurve;  ///< a turn-on's bins (acceptance_run.hpp)

/// One serial's acceptance figures with what the report draws them from beyond the structs.
struct SerialAcceptanceReport {
  SerialAcceptance figures;
  /// Per turn-on of the first power_cycles step (the ones the analysis took, in its order); each
  /// step's own are in figures.turn_on_steps.
  std::vector<WarmupCurve> warmups;
  /// Per positions step (figures.positions' order): the table angles the fit took, in its order,
  /// deg; empty when they could not be matched to the fit's positions.
  std::vector<std::vector<double>> position_angles_deg;
};

/// The test kinds that get a page.
enum class AcceptancePage { scale_factor, turn_on, positions };

/// The pages a run's acceptance figures give, in this order: scale factor (a ladder), turn-on
/// (power cycles), positions (a positions step, or a note why none was analysed).
std::vector<AcceptancePage> acceptance_pages(const std::vector<SerialAcceptanceReport>& a);

/// The page's title ("Scale factor", "Turn-on", "Positions") and its file-name part.
std::string acceptance_page_title(AcceptancePage p);
std::string acceptance_page_slug(AcceptancePage p);

/// The file name of run `run_id`'s acceptance page: run-ID-scale-factor.html etc.
std::string acceptance_page_name(std::int64_t run_id, AcceptancePage p);

/// Reads run `run_id`'s acceptance figures (acceptance_run.hpp) and each serial's warm-up curves
/// and position angles; empty when its protocol has no acceptance step.
std::vector<SerialAcceptanceReport> load_acceptance(Store& store, const RunRecord& run);

/// Fig. S1: each ladder's residuals from its least-squares line against the input rate, ppm of
/// full-scale output (compensation/scale_factor.hpp), a series per ladder; ladders not computed
/// named in the note with why.
Figure ladder_residuals_figure(std::string id, const SerialAcceptance& a);

/// Fig. S2: the scale factor per plateau against gyro temperature with its standard error, and
/// the fitted K(T) = K0 + s (T - T_ref) with its 1-sigma band, in ppm of K0; without a fit (one
/// plateau, or not computed) no points and the reason.
Figure sf_temperature_figure(std::string id, const SerialAcceptance& a);

/// The 1-sigma half-width of the fitted line K0 + s (T - T_ref) at `temp_c`, pulse/arcsec: the
/// covariance of (K0, s) is se_scale^2 (X'WX)^-1 with X = [1, T_i - T_ref], W = 1/SE(K_i)^2
/// (acceptance.hpp's covariance rule; its diagonal is the fit's own SE(K0)^2 and SE(s)^2).
double sf_line_se(const std::vector<LadderFigures>& ladders,
                  const compensation::ScaleFactorTemperatureFit& fit, double temp_c);

/// A serial's power_cycles steps as the turn-on page draws them, each with its own figures, bins
/// and band: figures.turn_on_steps, or (figures built without them) its one turn_on with
/// `warmups` as a step of step_index -1 (not computed, "no power cycles", without one).
std::vector<TurnOnStep> turn_on_steps_of(const SerialAcceptanceReport& a);

/// "hot (step 9, 70.0 °C)": a step's name on the page ("" for a step of step_index -1).
std::string turn_on_step_title(const TurnOnStep& s);

/// Fig. T1 of one power_cycles step: each turn-on's bias with its standard error, and the mean
/// with the +-sigma band of the turn-on-to-turn-on repeatability (compensation/turn_on.hpp).
Figure turn_on_figure(std::string id, const std::string& serial, const TurnOnStep& step);
/// Fig. T1 of the serial's first step ("no power cycles" without one).
Figure turn_on_figure(std::string id, const SerialAcceptance& a);

/// Fig. T2 of one power_cycles step: each turn-on's bias minus its final value against the time
/// since power-up (the step's bins), and the step's warm-up band around the final value (the
/// warm-up time is where a curve last leaves it).
Figure warmup_figure(std::string id, const std::string& serial, const TurnOnStep& step);
/// Fig. T2 of the serial's first step.
Figure warmup_figure(std::string id, const SerialAcceptanceReport& a);

/// Fig. P1: the Earth rate's projection on the input axis (the output minus the fitted bias)
/// against the table angle, per positions step, with its fitted sinusoid
/// (compensation/positions.hpp).
Figure positions_figure(std::string id, const SerialAcceptanceReport& a);

}  // namespace station::report
