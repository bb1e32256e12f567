// Writers of the coefficient block. Numbers are written with 17 significant digits (%.17g):
// every double reads back to itself, so a consumer's compensation equals the station's.
#include "station/release/block_formats.hpp"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <numbers>

#include "station/common/input_error.hpp"
#include "station/common/text_rule.hpp"

namespace station {
namespace {

using nlohmann::json;
namespace sc = station::compensation;

constexpr const char* kModel =
    "B = B0 + k1*dT + k2*dT^2 + k3*dT^3 + k4*dT^4 + k0*gradT, dT = clamp(T, t_min_c, t_max_c) - "
    "t_ref_c, gradT = clamp(T2 - T1, grad_min_c, grad_max_c); compensated = bias - B";

/// NAME_SERIAL_fitID: the fit id keeps serials that mangle alike ("A-1", "A_1") apart.
std::string c_identifier(const std::string& name, const CoefficientBlock& b) {
  std::string id = name + "_";
  for (const char c : b.serial.substr(0, 64))
    id += std::isalnum(static_cast<unsigned char>(c)) != 0 && static_cast<unsigned char>(c) < 0x80
              ? c
              : '_';
  return id + "_fit" + std::to_string(b.fit_id);
}

/// A C string literal: printable ASCII kept, everything else as an octal escape.
std::string c_string(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\')
      out += std::string("\\") + ch;
    else if (c >= 0x20 && c < 0x7f && c != '?')  // '?' escaped: no trigraphs
      out += ch;
    else
      out += fmt::format("\\{:03o}", c);
  }
  return out + "\"";
}

/// Text for a comment line of a C header or a parameter file: printable ASCII only (a newline
/// would end the comment; a bidirectional control fails -Werror=bidi-chars and can hide code
/// from a reviewer: every other character as "<U+XXXX>", common/text_rule.hpp), no "*/" or
/// "/*", no '?' (a C99 trigraph "??/" is a backslash that splices the next line into the
/// comment), no backslash; at most 200 characters.
std::string comment_safe(const std::string& s) {
  std::string out;
  for (const char ch : ascii_escaped(s).substr(0, 200)) out += ch == '?' || ch == '\\' ? '.' : ch;
  for (const char* pair : {"*/", "/*"})
    for (auto at = out.find(pair); at != std::string::npos; at = out.find(pair, at))
      out[at + 1] = ' ';
  return out;
}

/// A CSV text cell (RFC 4180: quoted when it holds a comma, quote, CR or LF; quotes doubled), as
/// valid UTF-8, and never a formula: a cell starting with = + - @ TAB or CR is what a spreadsheet
/// evaluates (OWASP "CSV Injection"), so it gets a leading apostrophe and quotes.
std::string csv_field(const std::string& text) {
  std::string s = valid_utf8(text);
  const bool formula = !s.empty() && std::string_view("=+-@\t\r").find(s[0]) != std::string::npos;
  if (formula) s.insert(0, "'");
  if (!formula && s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (const char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

/// The initializers after crc32 (gyro_tc/4), zeros when not measured: every field initialized
/// (-Wextra's missing-field-initializers stays quiet), so the header needs this gyro_tc.h.
std::string c_scale_factor(const gyro_tc_block& c) {
  if (c.sf_measured == 0)
    return ",\n    0, 0, 0, 0, 0, 0, 0, 0 /* scale factor: not measured (sf_measured 0) */";
  return fmt::format(
      ",\n    1, /* sf_measured */\n"
      "    {:.17g}, {:.17g}, /* sf_k0_pulse_per_arcsec, sf_tc_ppm_per_c */\n"
      "    {:.17g}, {:.17g}, {:.17g}, /* sf_t_ref_c, sf_t_min_c, sf_t_max_c */\n"
      "    {:.17g}, {:.17g} /* pulse_weight_arcsec, earth_rate_dph */",
      c.sf_k0_pulse_per_arcsec, c.sf_tc_ppm_per_c, c.sf_t_ref_c, c.sf_t_min_c, c.sf_t_max_c,
      c.pulse_weight_arcsec, c.earth_rate_dph);
}

std::string release_summary(const CoefficientBlock& b) {
  return comment_safe(b.release ? release_text(*b.release)
                                : "NOT RELEASED (exported with --fit; not the gyro's calibration)");
}

constexpr const char* kScaleModel =
    "K(T) = sf_k0*(1 + sf_tc_ppm*1e-6*(clamp(T, sf_t_min_c, sf_t_max_c) - sf_t_ref_c)) "
    "pulse/arcsec, "
    "s = K(T)*pulse_weight_arcsec; rate = (nominal_rate - B - earth_rate_dph)/s + earth_rate_dph, "
    "nominal_rate = pulses/s * pulse_weight_arcsec (deg/h); not measured: rate = nominal_rate - B";

/// The scale factor for people: one line, comment-safe.
std::string scale_factor_summary(const CoefficientBlock& b) {
  return comment_safe(scale_factor_text(b.scale_factor));
}

json scale_factor_json(const ScaleFactorSource& s) {
  if (!s.model) return {{"measured", false}, {"note", s.note}};
  const ScaleFactorModel& m = *s.model;
  return {{"measured", true},
          {"model", kScaleModel},
          {"k0_pulse_per_arcsec", m.k0_pulse_per_arcsec},
          {"k0_se_pulse_per_arcsec", m.k0_se_pulse_per_arcsec},
          {"tc_ppm_per_c", m.tc_ppm_per_c},
          {"tc_se_ppm_per_c", m.tc_se_ppm_per_c ? json(*m.tc_se_ppm_per_c) : json(nullptr)},
          {"t_ref_c", m.t_ref_c},
          {"span", {{"t_min_c", m.t_min_c}, {"t_max_c", m.t_max_c}}},
          {"outside_span", "clamp"},
          {"plateaus", m.plateaus},
          {"runs", m.runs},
          {"pulse_weight_arcsec", m.pulse_weight_arcsec},
          {"earth_rate_dph", m.earth_rate_dph},
          {"note", s.note}};
}

/// The CSV's scale-factor cells (the header's last 12 columns): empty numbers when not measured.
std::string scale_factor_cells(const ScaleFactorSource& s) {
  if (!s.model) return fmt::format("not measured,,,,,,,,,,,{}", csv_field(s.note));
  const ScaleFactorModel& m = *s.model;
  return fmt::format(
      "measured,{:.17g},{:.17g},{:.17g},{},{:.17g},{:.17g},{:.17g},{},{:.17g},{:.17g},{}",
      m.k0_pulse_per_arcsec, m.k0_se_pulse_per_arcsec, m.tc_ppm_per_c,
      m.tc_se_ppm_per_c ? fmt::format("{:.17g}", *m.tc_se_ppm_per_c) : "", m.t_ref_c, m.t_min_c,
      m.t_max_c, fmt::join(m.runs, ";"), m.pulse_weight_arcsec, m.earth_rate_dph,
      csv_field(s.note));
}

}  // namespace

std::string px4_scale_factor_note(const CoefficientBlock& b) {
  if (!b.scale_factor.model) return scale_factor_summary(b);
  return "SCALE FACTOR NOT IN THIS FILE: PX4's TC_G parameters hold no scale factor, so PX4 "
         "applies the bias alone (as gyro_tc_correct); export json, csv or c for it. Measured " +
         scale_factor_summary(b);
}

double dph_to_rad_per_s(double dph) {
  return dph * std::numbers::pi / (180.0 * 3600.0);
}

json block_json(const CoefficientBlock& b) {
  json coef = json::object(), se = json::object(), units = json::object();
  for (std::size_t i = 0; i < b.names.size(); ++i) {
    coef[b.names[i]] = b.coefficients[i];
    se[b.names[i]] = b.std_errors[i];
    units[b.names[i]] = std::string(sc::coefficient_unit(b.names[i]));
  }
  return {{"serial", b.serial},
          {"part_number", b.part_number.empty() ? json(nullptr) : json(b.part_number)},
          {"model", kModel},
          {"terms", b.names},
          {"coefficients", coef},
          {"std_errors", se},
          {"units", units},
          {"t_ref_c", b.t_ref_c},
          {"span",
           {{"t_min_c", b.t_min_c},
            {"t_max_c", b.t_max_c},
            {"grad_min_c", b.grad_min_c},
            {"grad_max_c", b.grad_max_c}}},
          {"outside_span", "clamp"},
          {"bin_s", b.bin_s ? json(*b.bin_s) : json(nullptr)},
          {"runs", b.runs},
          {"fit_id", b.fit_id},
          {"fit_created_utc", b.fit_created_utc},
          {"std_after_dph", b.std_after_dph},
          {"std_ratio", b.std_ratio ? json(*b.std_ratio) : json(nullptr)},
          {"verdict", b.verdict_json ? json::parse(*b.verdict_json) : json(nullptr)},
          {"model_choice", b.model_choice_json ? json::parse(*b.model_choice_json) : json(nullptr)},
          {"scale_factor", scale_factor_json(b.scale_factor)},
          {"released", b.release.has_value()},
          {"release", b.release ? release_json(*b.release) : json(nullptr)},
          {"software_version", b.software_version},
          {"checksum",
           {{"algorithm", "CRC-32/ISO-HDLC of canonical (gyro_tc.h, gyro_tc_canonical)"},
            {"canonical", b.canonical},
            {"crc32", fmt::format("0x{:08x}", b.crc32)}}}};
}

std::string blocks_csv(const std::vector<CoefficientBlock>& blocks) {
  std::string out =
      "serial,part_number,fit_id,term,value,std_error,unit,t_ref_c,t_min_c,t_max_c,grad_min_c,"
      "grad_max_c,outside_span,bin_s,runs,verdict,failed_limits,released,released_utc,released_by,"
      "note,override,"
      "software_version,crc32,scale_factor,sf_k0_pulse_per_arcsec,sf_k0_se_pulse_per_arcsec,"
      "sf_tc_ppm_per_c,sf_tc_se_ppm_per_c,sf_t_ref_c,sf_t_min_c,sf_t_max_c,sf_runs,"
      "pulse_weight_arcsec,earth_rate_dph,sf_note\n";
  for (const auto& b : blocks) {
    // The verdict on every row (a CSV has no header block): pass, fail or empty for no part,
    // and the failed limits joined by ';'.
    const json v = b.verdict_json ? json::parse(*b.verdict_json) : json();
    const std::string verdict = v.is_null() ? "" : (v.value("pass", false) ? "pass" : "fail");
    std::string failed;
    if (v.is_object())
      for (const auto& f : v.value("failed", json::array()))
        failed += (failed.empty() ? "" : ";") + f.value("limit", std::string("?"));
    for (std::size_t i = 0; i < b.names.size(); ++i) {
      out += fmt::format(
          "{},{},{},{},{:.17g},{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},clamp,{},{},{},{}"
          ","
          "{},{},{},{},{},{},0x{:08x},{}\n",
          csv_field(b.serial), csv_field(b.part_number), b.fit_id, b.names[i], b.coefficients[i],
          b.std_errors[i], sc::coefficient_unit(b.names[i]), b.t_ref_c, b.t_min_c, b.t_max_c,
          b.grad_min_c, b.grad_max_c, b.bin_s ? fmt::format("{:g}", *b.bin_s) : "",
          fmt::join(b.runs, ";"), verdict, failed, b.release ? "yes" : "NO",
          b.release ? b.release->released_utc : "",
          csv_field(b.release ? b.release->released_by : ""),
          csv_field(b.release ? b.release->note : ""),
          csv_field(b.release && b.release->override_reason ? *b.release->override_reason : ""),
          b.software_version, b.crc32, scale_factor_cells(b.scale_factor));
    }
  }
  return out;
}

std::string blocks_c_header(const std::vector<CoefficientBlock>& blocks, const std::string& name) {
  std::string guard;
  for (const char c : name) guard += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  std::string out = fmt::format(
      "/* Gyro thermal-bias calibrations, written by `station export --format c` (station {}).\n"
      " * Apply with gyro_tc_rate_dph() (bias and scale factor) or gyro_tc_correct() (bias) from\n"
      " * gyro_tc.h; check each with gyro_tc_verify() first.\n"
      " * Model: {}.\n * Scale factor: {} */\n"
      "#ifndef {}_H\n#define {}_H\n\n#include \"gyro_tc.h\"\n",
      blocks.empty() ? "" : blocks.front().software_version, kModel, kScaleModel, guard, guard);
  std::string table;
  for (const auto& b : blocks) {
    const gyro_tc_block c = b.c_block();
    out += fmt::format(
        "\n/* {}: fit {} over runs {}, terms {}; {}; verdict {}\n * {} */\n"
        "static const gyro_tc_block {} = {{\n"
        "    {}, {}, {}LL, {}, /* serial, part, fit, released */\n"
        "    {:.17g}, /* t_ref_c */\n"
        "    {:.17g}, {:.17g}, /* t_min_c, t_max_c */\n"
        "    {:.17g}, {:.17g}, /* grad_min_c, grad_max_c */\n"
        "    {:.17g}, /* b0_dph */\n"
        "    {{{:.17g}, {:.17g}, {:.17g}, {:.17g}}}, /* k1..k4 */\n"
        "    {:.17g}, /* k0_dph_per_c */\n"
        "    0x{:08x}u{}}};\n",
        comment_safe(b.serial), b.fit_id, fmt::join(b.runs, ","), comment_safe(b.terms),
        release_summary(b),
        !b.verdict_json ? "none"
                        : (json::parse(*b.verdict_json).value("pass", false) ? "pass" : "FAIL"),
        scale_factor_summary(b), c_identifier(name, b), c_string(b.serial), c_string(b.part_number),
        b.fit_id, c.released, c.t_ref_c, c.t_min_c, c.t_max_c, c.grad_min_c, c.grad_max_c, c.b0_dph,
        c.k_dph[0], c.k_dph[1], c.k_dph[2], c.k_dph[3], c.k0_dph_per_c, c.crc32, c_scale_factor(c));
    table += fmt::format("    &{},\n", c_identifier(name, b));
  }
  out += fmt::format(
      "\nstatic const gyro_tc_block *const {}_blocks[] = {{\n{}}};\n"
      "#define {}_BLOCK_COUNT {}\n\n#endif /* {}_H */\n",
      name, table, guard, blocks.size(), guard);
  return out;
}

std::string block_px4(const CoefficientBlock& b, Px4Slot slot) {
  for (const auto* name : {"k0", "k4"}) {
    if (b.coefficient_or_zero(name) != 0.0)
      throw InputError(fmt::format(
          "export --format px4: fit {} of {} has {} ({}): PX4's TC_G model is a cubic in dT "
          "alone; export json, csv or c, or fit --terms dT,dT2,dT3",
          b.fit_id, b.serial, name, name == std::string("k0") ? "the gradient term" : "dT^4"));
  }
  if (slot.instance < 0 || slot.instance > 3 || slot.axis < 0 || slot.axis > 2)
    throw InputError("export --format px4: --px4-instance must be 0..3 and --px4-axis 0..2");
  const std::string g = fmt::format("TC_G{}_", slot.instance);
  std::string out = fmt::format(
      "# Gyro thermal compensation for PX4 (TC_G* layout, one axis), `station export --format "
      "px4`\n# serial {}, fit {} over runs {}, {}, crc32 0x{:08x}\n"
      "# Units: rad/s (converted from deg/h). PX4 subtracts X0 + X1 dT + X2 dT^2 + X3 dT^3, "
      "dT = clamp(T, TMIN, TMAX) - TREF;\n# TC_G{}_ID is 0: set it to the sensor's device id. "
      "Enable with TC_G_ENABLE = 1.\n# {}\n# Vehicle-Id Component-Id Name Value Type\n",
      comment_safe(b.serial), b.fit_id, fmt::join(b.runs, ","), release_summary(b), b.crc32,
      slot.instance, px4_scale_factor_note(b));
  const auto row = [&out](const std::string& name, double v) {
    out += fmt::format("1\t1\t{}\t{:.17g}\t9\n", name, v);
  };
  out += fmt::format("1\t1\t{}ID\t0\t6\n", g);
  row(g + "TMAX", b.t_max_c);
  row(g + "TMIN", b.t_min_c);
  row(g + "TREF", b.t_ref_c);
  row(fmt::format("{}X0_{}", g, slot.axis), dph_to_rad_per_s(b.coefficient_or_zero("B0")));
  for (int i = 1; i <= 3; ++i)
    row(fmt::format("{}X{}_{}", g, i, slot.axis),
        dph_to_rad_per_s(b.coefficient_or_zero(fmt::format("k{}", i))));
  return out;
}

}  // namespace station
