// From stored samples to stored coefficients: 600 s bins per gyro (Earth rate removed per slot),
// then the thermal model fitted per serial number over one or several runs.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "compensation/fit.hpp"
#include "station/store/store.hpp"

namespace station {

/// The bin width a run recorded (runs.resolved_json "bin_s", migration 2); empty when it did not.
std::optional<double> recorded_bin_s(const RunRecord& run);
/// The bin width of a run: its own, or the paper's (compensation::kPaperBinS) for a run recorded
/// before it was kept.
double run_bin_s(const RunRecord& run);

/// One gyro's 1 Hz record in `run_id` as model input: bias (rate - the slot's Earth rate),
/// temperature, gradient (temp2 - temp), over the samples that go into bins (gaps closed up).
compensation::ModelData record_model_data(Store& store, std::int64_t run_id,
                                          const std::string& serial);

/// The same over the samples of the run's complete stored bins only (what a fit saw): a sample
/// belongs to the bin [t_start_s, t_start_s + bin_s) of the run's bin width.
compensation::ModelData fitted_record_model_data(Store& store, std::int64_t run_id,
                                                 const std::string& serial);

/// Bins one gyro's samples of the record window (recording = true) at bin_s.
std::vector<compensation::Bin> bin_samples(const std::vector<SampleRow>& rows, double bin_s);

/// Bins every slot's recorded samples of `run_id` (bin width bin_s) and stores them.
/// The gradient is temp2 - temp per sample; samples without rate or temperatures, or flagged
/// safe-hold or board fault (kUnfitFlags), are skipped, so their bins come out incomplete.
void bin_run(Store& store, std::int64_t run_id, double bin_s);

/// One serial's fit as stored.
struct SerialFit {
  std::string serial;
  std::vector<std::int64_t> runs;
  compensation::FitResult fit;
  compensation::Evaluation eval;
  std::int64_t fit_id = 0;
};

/// Fits `spec` to the complete bins of `serial` over `runs` (all its runs when empty), stores the
/// fit with its statistics and the runs used. `warnings` are stored with the fit's own; a run
/// that ended 'incomplete' adds one. Throws InputError when there is nothing to fit.
SerialFit fit_serial(Store& store, const std::string& serial, std::vector<std::int64_t> runs,
                     const compensation::ModelSpec& spec, std::vector<std::string> warnings = {});

}  // namespace station
