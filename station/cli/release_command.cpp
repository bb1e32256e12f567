// `station release` (a fit becomes the gyro's calibration), `station export` (the released
// calibration as a coefficient block for the navigation computer) and `station verify` (a fit
// applied to a run it was not fitted on).
#include <fmt/format.h>

#include <cctype>
#include <iostream>
#include <nlohmann/json.hpp>

#include "station/cli/acceptance_beside.hpp"
#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/cli/text_options.hpp"
#include "station/common/input_error.hpp"
#include "station/common/text_rule.hpp"
#include "station/parts/judged_fit.hpp"
#include "station/release/block_formats.hpp"
#include "station/release/releases.hpp"
#include "station/release/verification.hpp"

namespace station {
namespace {

struct ReleaseOptions {
  std::string db, by, note;
  std::optional<std::string> override_reason;
  std::int64_t fit_id = 0;
};

struct ExportOptions {
  std::string db, format = "json", c_name = "gyro_tc_calibrations";
  std::vector<std::string> serials;
  std::optional<std::int64_t> fit_id;
  Px4Slot px4;
};

struct VerifyOptions {
  std::string db, serial, parts, part;
  std::int64_t run_id = 0;
  std::optional<std::int64_t> fit_id;
  bool json = false;
  bool redo = false;  ///< verify again and store a new verification beside the stored one
};

void run_release(const ReleaseOptions& o) {
  Store store(o.db, OpenMode::existing);
  const ReleaseRow r = release_fit(store, {o.fit_id, o.by, o.note, o.override_reason});
  fmt::print("{}: fit {} is the released calibration ({}, release {})\n", r.serial, r.fit_id,
             release_text(r), r.id);
  // What `export` will carry beside the bias model (gyro_tc/4), or that it leaves the scale alone.
  if (const auto fit = store.find_fit(r.fit_id))
    fmt::print("  {}\n", scale_factor_text(find_scale_factor(store, *fit)));
  if (r.override_reason)
    fmt::print(stderr, "station: warning: fit {} released over its verdict: {}\n", r.fit_id,
               *r.override_reason);
}

/// The block `station export` writes for one serial: its released fit, or --fit ID.
CoefficientBlock export_block(Store& store, const ExportOptions& o, const std::string& serial) {
  if (!o.fit_id) {
    const auto released = current_release(store, serial);
    if (!released)
      throw InputError(fmt::format(
          "{}: serial '{}' has no released calibration (`station release --fit ID --by NAME`; "
          "`station export --fit ID` exports a fit that is not released)",
          o.db, serial));
    const auto fit = store.find_fit(released->fit_id);
    if (!fit)
      throw InputError(fmt::format("{}: released fit {} is missing", o.db, released->fit_id));
    return make_block(store, *fit, released);
  }
  const auto fit = store.find_fit(*o.fit_id);
  if (!fit) throw InputError(fmt::format("{}: no fit {}", o.db, *o.fit_id));
  if (!serial.empty() && fit->serial != serial)
    throw InputError(fmt::format("{}: fit {} is of serial '{}', not '{}'", o.db, *o.fit_id,
                                 fit->serial, serial));
  const auto released = current_release(store, fit->serial);
  const bool is_released = released && released->fit_id == fit->id;
  if (!is_released)
    fmt::print(stderr,
               "station: warning: fit {} is NOT the released calibration of {} ({}); the export "
               "says so ({})\n",
               fit->id, fit->serial,
               released ? fmt::format("fit {} is", released->fit_id) : std::string("none is"),
               o.format == "json"  ? "\"released\": false"
               : o.format == "csv" ? "released NO"
               : o.format == "c"   ? "released = 0, in the checksum"
                                   : "a comment: PX4 parameters cannot say it");
  return make_block(store, *fit, is_released ? released : std::nullopt);
}

void run_export(const ExportOptions& o) {
  if (o.serials.empty() && !o.fit_id) throw InputError("export: give --serial SN or --fit ID");
  if (o.fit_id && o.serials.size() > 1)
    throw InputError("export: --fit ID names one fit: give at most one --serial");
  if (o.format == "px4" && o.serials.size() > 1)
    throw InputError("export --format px4: one gyro axis per file: give one --serial");
  for (std::size_t i = 0; i < o.serials.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (o.serials[i] == o.serials[j])
        throw InputError(fmt::format("export: serial '{}' named twice", o.serials[i]));
  if (o.c_name.empty() || std::isdigit(static_cast<unsigned char>(o.c_name[0])) ||
      o.c_name.find_first_not_of(
          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") != std::string::npos ||
      o.c_name.size() > 64)
    throw InputError(fmt::format("export --c-name '{}': expected a C identifier", o.c_name));
  Store store(o.db, OpenMode::read_only);
  std::vector<CoefficientBlock> blocks;
  if (o.serials.empty()) blocks.push_back(export_block(store, o, ""));
  for (const auto& s : o.serials) blocks.push_back(export_block(store, o, s));
  store.db().check_unchanged();
  if (o.format == "csv") {
    std::cout << blocks_csv(blocks);
  } else if (o.format == "c") {
    std::cout << blocks_c_header(blocks, o.c_name);
  } else if (o.format == "px4") {
    std::cout << block_px4(blocks.front(), o.px4);
    if (blocks.front().scale_factor.model)
      fmt::print(stderr, "station: warning: {}: {}\n", blocks.front().serial,
                 px4_scale_factor_note(blocks.front()));
  } else {
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& b : blocks) arr.push_back(block_json(b));
    // Valid UTF-8 out whatever an older record holds (a byte that is not UTF-8 becomes U+FFFD
    // instead of ending the export in json's type_error.316).
    std::cout << (arr.size() == 1 ? arr[0] : arr)
                     .dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
              << '\n';
  }
}

void print_verification(const VerificationResult& v) {
  fmt::print("{}: fit {} applied to run {} ({} bins, {} outside the fit's span, clamped)\n",
             v.serial, v.fit_id, v.run_id, v.bins, v.clamped_bins);
  fmt::print("  std before {:.5f} deg/h, after {:.5f} deg/h, ratio {}\n", v.eval.std_before_dph,
             v.eval.std_after_dph,
             v.eval.std_ratio ? fmt::format("{:.3f}", *v.eval.std_ratio) : "undefined");
  fmt::print("  mean residual {:+.5f} deg/h\n", v.mean_residual_dph);
  if (v.drift_dph_per_c)
    fmt::print("  residual drift {:+.3e} +- {:.1e} deg/h/C (against T)\n", *v.drift_dph_per_c,
               *v.drift_se_dph_per_c);
  if (v.adev_floor_dph)
    fmt::print("  ADEV floor {:.5f} deg/h (compensated 1 Hz record)\n", *v.adev_floor_dph);
  for (const auto& w : v.warnings) fmt::print("  warning: {}\n", w);
  fmt::print("  verdict: {} (verification {})\n", verdict_text(v.verdict), v.id);
}

// The fit to verify: --fit ID (of this serial), else the serial's released calibration.
FitRecord fit_to_verify(Store& store, const VerifyOptions& o) {
  if (o.fit_id) {
    auto fit = store.find_fit(*o.fit_id);
    if (!fit) throw InputError(fmt::format("{}: no fit {}", o.db, *o.fit_id));
    if (fit->serial != o.serial)
      throw InputError(fmt::format("{}: fit {} is of serial '{}', not '{}'", o.db, *o.fit_id,
                                   fit->serial, o.serial));
    return std::move(*fit);
  }
  const auto rel = current_release(store, o.serial);
  if (!rel)
    throw InputError(fmt::format(
        "{}: serial '{}' has no released calibration (give --fit ID to verify another fit)", o.db,
        o.serial));
  return *store.find_fit(rel->fit_id);
}

void print_verify(Store& store, const VerifyOptions& o, const VerificationResult& v, bool reused) {
  // The verification run's acceptance figures, judged when it ended (issue 36).
  const auto acceptance = acceptance_beside_json(store, v.serial, {v.run_id});
  if (o.json) {
    auto j = verification_json(v);
    j["verification_id"] = v.id;
    j["created_utc"] = v.created_utc;
    j["stored_before"] = reused;
    j["acceptance"] = acceptance;
    std::cout << j.dump(2) << '\n';
    return;
  }
  print_verification(v);
  fmt::print("{}", acceptance_beside_text(acceptance));
  if (reused)
    fmt::print("  (stored {}: the same fit on the same run; --redo verifies it again)\n",
               v.created_utc);
}

int run_verify(const VerifyOptions& o) {
  std::optional<PartFile> parts;
  if (!o.parts.empty()) parts = load_part_file(o.parts);
  Store store(o.db, OpenMode::existing);
  const FitRecord fit = fit_to_verify(store, o);
  const auto limits = limits_for(store, o.serial, {o.run_id}, {parts ? &*parts : nullptr, o.part});
  if (parts && !limits)
    throw InputError(
        fmt::format("verify: --parts {}: run {}'s slot of '{}' names no part: give "
                    "--part PN",
                    o.parts, o.run_id, o.serial));
  // The same fit on the same run against the same part gives the same figures: the stored
  // verification is reported, not stored again, unless --redo asks for a new one.
  auto stored = o.redo ? std::nullopt : stored_verification(store, fit.id, o.run_id, limits);
  const bool reused = stored.has_value();
  VerificationResult v = reused ? std::move(*stored) : verify_fit(store, fit, o.run_id, limits);
  if (!reused) save_verification(store, v);
  print_verify(store, o, v, reused);
  return v.verdict && !v.verdict->pass ? 1 : 0;
}

void add_release(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<ReleaseOptions>();
  auto* c = app.add_subcommand("release", "Make a fit the gyro's released calibration");
  c->footer(exit_status_footer({{0, "the fit is the released calibration"}}));
  c->add_option("--db", o->db, "SQLite database")->required();
  c->add_option("--fit", o->fit_id, "fit id (station fit / history)")->required();
  c->add_option("--by", o->by, "who releases")->required()->check(note_text(kMaxPersonBytes));
  c->add_option("--note", o->note, "free text stored with the release")
      ->check(note_text(kMaxNoteBytes));
  c->add_option("--override", o->override_reason,
                "release a fit whose verdict failed (or is missing) anyway, for this reason")
      ->check(note_text(kMaxNoteBytes));
  c->callback([o, &status] {
    run_release(*o);
    status.exit_code = 0;
  });
}

void add_export(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<ExportOptions>();
  auto* c = app.add_subcommand(
      "export", "Write the released calibration of gyros for the navigation computer");
  c->footer(exit_status_footer({{0, "the released calibration was written"}}));
  c->add_option("--db", o->db, "SQLite database")->required();
  c->add_option("--serial", o->serials, "gyro serial number(s)")->delimiter(',');
  c->add_option("--fit", o->fit_id, "export this fit (warns when it is not the released one)");
  c->add_option("--format", o->format, "json|csv|c|px4")
      ->check(CLI::IsMember({"json", "csv", "c", "px4"}))
      ->capture_default_str();
  c->add_option("--c-name", o->c_name,
                "c: prefix of the header's names (NAME_blocks, NAME_BLOCK_COUNT, guard NAME_H)")
      ->capture_default_str();
  c->add_option("--px4-instance", o->px4.instance, "px4: gyro instance (TC_G<N>), 0..3")
      ->capture_default_str();
  c->add_option("--px4-axis", o->px4.axis, "px4: board axis of this gyro, 0 x, 1 y, 2 z")
      ->capture_default_str();
  c->callback([o, &status] {
    run_export(*o);
    status.exit_code = 0;
  });
}

void add_verify(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<VerifyOptions>();
  auto* c = app.add_subcommand("verify", "Apply a calibration to a run it was not fitted on");
  c->footer(
      exit_status_footer({{0, "verified: the verdict passed, or there are no limits to judge"},
                          {1, "the verdict failed (the result is stored)"}}));
  c->add_option("--db", o->db, "SQLite database")->required();
  c->add_option("--serial", o->serial, "gyro serial number")->required();
  c->add_option("--run", o->run_id, "the independent run")->required();
  c->add_option("--fit", o->fit_id, "fit id (default: the released calibration)");
  c->add_option("--parts", o->parts, "part file (default: the limits stored with the run)");
  c->add_option("--part", o->part, "part number (default: the one the run's slot named)");
  c->add_flag("--json", o->json, "print JSON");
  c->add_flag("--redo", o->redo,
              "verify again and store a new verification (default: report the stored one of "
              "this fit on this run and part)");
  c->callback([o, &status] { status.exit_code = run_verify(*o); });
}

}  // namespace

void add_release_commands(CLI::App& app, CommandStatus& status) {
  add_release(app, status);
  add_export(app, status);
  add_verify(app, status);
}

}  // namespace station
