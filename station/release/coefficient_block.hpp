// The coefficient block: everything a navigation computer needs to apply one gyro's
// calibration correctly, built once from the store and written in every export format
// (block_formats.hpp). Its numbers and their checksum are defined by the shipped C header
// gyro_tc.h (gyro_tc_canonical, gyro_tc_crc32): the station computes the checksum with the same
// code a consumer runs.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "compensation/fit.hpp"
#include "station/release/gyro_tc.h"
#include "station/release/releases.hpp"
#include "station/release/scale_factor_source.hpp"
#include "station/store/store.hpp"

namespace station {

/// Why a fit's model cannot travel in a block (a term gyro_tc_correct does not apply: dTdt,
/// channel, gradTdT); empty when it can.
std::optional<std::string> undeliverable_term(const compensation::FitResult& fit);

/// One gyro's calibration as delivered.
struct CoefficientBlock {
  std::string serial, part_number;  ///< part_number empty: judged against no part
  std::int64_t fit_id = 0;
  std::string fit_created_utc, terms;            ///< terms as fitted ("dT,gradT")
  std::vector<std::int64_t> runs;                ///< the runs the fit used
  std::vector<std::string> names;                ///< coefficient names in model order
  std::vector<double> coefficients, std_errors;  ///< by names
  double t_ref_c = 0;                            ///< T_ref, deg C
  double t_min_c = 0, t_max_c = 0;               ///< span of T the fit saw, deg C
  double grad_min_c = 0, grad_max_c = 0;         ///< span of gradT the fit saw, deg C
  std::optional<double> bin_s;                   ///< bin length (empty: runs differ)
  std::optional<double> std_ratio;               ///< in-sample std after / before
  double std_after_dph = 0;                      ///< in-sample std after, deg/h
  std::optional<std::string> verdict_json;       ///< the fit's verdict (empty: none)
  /// How the fit's model was chosen (fits.model_choice_json; empty: terms given by hand).
  std::optional<std::string> model_choice_json;
  /// The scale-factor model (gyro_tc/4) or why there is none (find_scale_factor).
  ScaleFactorSource scale_factor;
  std::optional<ReleaseRow> release;  ///< empty: exported without release
  std::string software_version;       ///< the station's version
  std::uint32_t crc32 = 0;            ///< of canonical
  std::string canonical;              ///< gyro_tc_canonical's text

  /// The block as gyro_tc.h holds it; points into this object's strings.
  gyro_tc_block c_block() const;
  /// Value of coefficient `name`, 0 when the model lacks it (gyro_tc.h's rule).
  double coefficient_or_zero(const std::string& name) const;
};

/// Builds the block of a stored fit, with the serial's scale factor (find_scale_factor): the spans
/// are the min and max of T and gradT over the 1 Hz samples of the fit's complete bins, as stored
/// with the fit (FitRecord::span; found from the samples only for a fit stored before migration 8),
/// so every bin mean the fit used and every sample in it lies inside them. Throws ReleaseRefused
/// for an undeliverable term, and InputError when the fit's runs hold no such sample, a value is
/// not finite, or the canonical text would not fit GYRO_TC_CANONICAL_MAX.
CoefficientBlock make_block(Store& store, const FitRecord& fit,
                            const std::optional<ReleaseRow>& release);

/// The checksum fields of `b`, recomputed from its numbers (fills canonical and crc32).
void seal_block(CoefficientBlock& b);

}  // namespace station
