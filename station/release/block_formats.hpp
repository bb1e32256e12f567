// The coefficient block written for its consumers: JSON (one object per serial), CSV (one row
// per coefficient, the block's fields on every row), a C header (one `const gyro_tc_block` per
// serial, for gyro_tc.h) and a PX4 parameter file (the TC_G* layout for one gyro axis, which has
// no scale factor: the file says so).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "station/release/coefficient_block.hpp"

namespace station {

/// The block as JSON: serial, part_number, model, terms, coefficients, std_errors, units,
/// t_ref_c, span {t_min_c, t_max_c, grad_min_c, grad_max_c}, outside_span "clamp", bin_s,
/// runs, fit_id, verdict, scale_factor {measured, note; when measured: model,
/// k0_pulse_per_arcsec, tc_ppm_per_c with SEs, t_ref_c, span, runs, pulse_weight_arcsec,
/// earth_rate_dph}, release, software_version, checksum {algorithm, canonical, crc32}.
nlohmann::json block_json(const CoefficientBlock& b);

/// CSV: a header line, then one row per coefficient of each block; the scale factor (or "not
/// measured") in the last 12 columns of every row.
std::string blocks_csv(const std::vector<CoefficientBlock>& blocks);

/// A C header: `#include "gyro_tc.h"`, then one `static const gyro_tc_block NAME_<SERIAL>_fit<ID>`
/// per block (serial mangled to an identifier), a table NAME_blocks and NAME_BLOCK_COUNT; the
/// include guard is NAME_H in capitals. `name` must be a C identifier (export --c-name).
std::string blocks_c_header(const std::vector<CoefficientBlock>& blocks,
                            const std::string& name = "gyro_tc_calibrations");

/// Where a PX4 block goes: gyro instance (TC_G<instance>) and board axis (0 x, 1 y, 2 z).
struct Px4Slot {
  int instance = 0, axis = 0;
};
/// A QGroundControl parameter file (PX4 Tools/process_sensor_caldata.py's .params layout:
/// "vehicle\tcomponent\tname\tvalue\ttype", type 6 int32, 9 float) with TC_G<i>_TMIN, TMAX,
/// TREF and X0..X3 of one axis in rad/s. PX4's model is a cubic in dT alone: a block with a
/// gradient or a dT^4 term is refused (InputError), never silently truncated. It has no scale
/// factor either: the bias alone is a correct model by itself (gyro_tc_correct), so a measured
/// scale factor is not refused but left out, and a comment line says so (px4_scale_factor_note).
std::string block_px4(const CoefficientBlock& b, Px4Slot slot);

/// The PX4 file's line on the scale factor: that it is left out (with its value), or not measured.
std::string px4_scale_factor_note(const CoefficientBlock& b);

/// deg/h -> rad/s (PX4 gyro units): pi / (180 * 3600).
double dph_to_rad_per_s(double dph);

}  // namespace station
