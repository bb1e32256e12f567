// The fleet's runs as estimates of their part's noise (`station fleet --propose-noise`): for each
// run and serial of a part, the newest fit that used the run, its model applied to the run's 1 Hz
// samples, and the IEEE 952 terms of that compensated record (noise_proposal.hpp says which and
// why). A run with no estimate (its run row, slot or samples not in the database, too short a
// record, no ARW term) is kept with the reason, never dropped. Reads PostgreSQL; blocks.
#pragma once

#include <vector>

#include "compensation/fit.hpp"
#include "station/fleet/fleet_charts.hpp"
#include "station/fleet/noise_proposal.hpp"
#include "station/fleet/pg.hpp"
#include "station/store/store.hpp"

namespace station::fleet {

/// 1 Hz samples of the record window a run needs for an estimate: at least 30 averages at an
/// averaging time of 30 s, where the ARW still dominates the Allan curve of an RLG.
inline constexpr std::size_t kMinNoiseSamples = 900;

/// The terms of one run's compensated record, or why there are none. `samples` are the run's
/// rows of one serial (any window; the record window is taken), `fit` the model compensating
/// them, `bin_s` the run's bin width (for a dT/dt term). Pure.
RunNoise estimate_run_noise(RunNoise r, const std::vector<SampleRow>& samples,
                            double earth_rate_dph, const compensation::FitResult& fit,
                            double bin_s);

/// Every (run, serial) of the parts the filter selects that a fit with a part number used, each
/// with its estimate or problem. Blocks on PostgreSQL; throws PgError.
std::vector<RunNoise> fleet_run_noise(PgConnection& pg, const ChartFilter& filter);

}  // namespace station::fleet
