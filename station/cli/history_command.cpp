// `station history (--db DB | --pg URL) --serial SN [--json]`: every run and fit of one gyro,
// its coefficients over time, their run-to-run scatter against the reported uncertainties, and
// calibrations that moved more than their uncertainties allow. Read-only. With --pg, across the
// fleet: every station's runs and fits as forwarded to the central PostgreSQL (ids are the
// fleet's, each row names its station).
#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "station/acceptance/acceptance_history.hpp"
#include "station/acceptance/acceptance_json.hpp"
#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/common/input_error.hpp"
#include "station/config/fleet_config.hpp"
#include "station/fleet/fleet_acceptance.hpp"
#include "station/fleet/fleet_history.hpp"
#include "station/parts/history.hpp"
#include "station/parts/verdict.hpp"
#include "station/release/releases.hpp"

namespace station {
namespace {

using nlohmann::json;

struct HistoryOptions {
  std::string db, pg, serial;
  bool json = false;
};

json opt(const std::optional<double>& v) {
  return v ? json(*v) : json();
}

std::optional<Verdict> verdict_of(const SerialFitRow& f) {
  if (!f.verdict_json) return std::nullopt;
  return verdict_from_json(json::parse(*f.verdict_json));
}

json fit_row_json(const SerialFitRow& f) {
  json coef = json::object(), se = json::object();
  for (const auto& [n, v] : f.coefficients) coef[n] = v;
  for (const auto& [n, v] : f.std_errors) se[n] = v;
  const auto v = verdict_of(f);
  return {{"fit_id", f.fit_id},
          {"created_utc", f.created_utc},
          {"runs", f.runs},
          {"terms", f.terms},
          {"bins", f.n_bins},
          {"coefficients", coef},
          {"std_errors", se},
          {"std_after_dph", f.std_after_dph},
          {"std_ratio", opt(f.std_ratio)},
          {"part_number", f.part_number ? json(*f.part_number) : json()},
          {"verdict", v ? verdict_json(*v) : json()},
          {"station", f.station.empty() ? json() : json(f.station)}};
}

json releases_json(const std::vector<ReleaseRow>& releases) {
  json out = json::array();
  for (const auto& r : releases) {
    out.push_back(release_json(r));
    out.back()["current"] = &r == &releases.back();
  }
  return out;
}

json history_json(const std::string& serial, const std::vector<SerialRun>& runs,
                  const std::vector<SerialFitRow>& fits, const SerialHistoryStats& h,
                  const std::vector<ReleaseRow>& releases) {
  json jr = json::array(), jf = json::array(), jc = json::array(), js = json::array(),
       jflags = json::array();
  for (const auto& r : runs) {
    jr.push_back({{"run_id", r.run_id},
                  {"started_utc", r.started_utc},
                  {"ended_utc", r.ended_utc},
                  {"state", r.state},
                  {"protocol", r.protocol_name},
                  {"station", r.station},
                  {"operator", r.operator_name},
                  {"slot", r.slot},
                  {"part_number", r.part_number ? json(*r.part_number) : json()}});
  }
  for (const auto& f : fits) jf.push_back(fit_row_json(f));
  for (const auto& c : h.calibrations) jc.push_back(c.fit->fit_id);
  for (const auto& s : h.scatter) {
    js.push_back({{"coefficient", s.coefficient},
                  {"n", s.n},
                  {"mean", s.n > 0 ? json(s.mean) : json()},
                  {"sample_std", opt(s.sample_std)},
                  {"rms_se", opt(s.rms_se)},
                  {"chi2", opt(s.chi2)},
                  {"birge_ratio", opt(s.birge_ratio)}});
  }
  for (const auto& f : h.flags) {
    jflags.push_back({{"fit_id", f.fit_id},
                      {"previous_fit_id", f.previous_fit_id},
                      {"coefficient", f.coefficient},
                      {"delta", f.delta},
                      {"zeta", f.zeta}});
  }
  return {{"serial", serial},
          {"runs", jr},
          {"fits", jf},
          {"calibrations", jc},
          {"terms", h.terms},
          {"scatter", js},
          {"drift_limit_zeta", kDriftZetaLimit},
          {"drift", jflags},
          {"released_fit_id", releases.empty() ? json() : json(releases.back().fit_id)},
          {"releases", releases_json(releases)}};
}

std::string pm(const SerialFitRow& f, const std::string& name) {
  const auto v = f.coefficient(name), u = f.std_error(name);
  if (!v) return "-";
  return u ? fmt::format("{:.4e} +- {:.1e}", *v, *u) : fmt::format("{:.4e}", *v);
}

void print_releases(const std::vector<ReleaseRow>& releases) {
  if (releases.empty()) {
    fmt::print("  no fit released (`station release --fit ID --by NAME`)\n");
    return;
  }
  for (const auto& r : releases)
    fmt::print("  {} fit {}: {}\n", &r == &releases.back() ? "RELEASED  " : "superseded", r.fit_id,
               release_text(r));
}

void print_history(const std::string& serial, const std::vector<SerialRun>& runs,
                   const std::vector<SerialFitRow>& fits, const SerialHistoryStats& h,
                   const std::vector<ReleaseRow>& releases) {
  const std::int64_t released = releases.empty() ? 0 : releases.back().fit_id;
  fmt::print("{}: {} runs, {} fits, {} calibrations\n", serial, runs.size(), fits.size(),
             h.calibrations.size());
  for (const auto& r : runs) {
    fmt::print("  run {:>4} {} {:<10} {:<12} slot {:>2} part {} station {}\n", r.run_id,
               r.started_utc, r.state, r.protocol_name, r.slot, r.part_number.value_or("-"),
               r.station);
  }
  fmt::print("  {:>6} {:<24} {:<10} {:>24} {:>24} {:>7}  verdict\n", "fit", "created", "runs",
             "k1 deg/h/C", "k0 deg/h/C", "ratio");
  for (const auto& f : fits) {
    fmt::print("  {:>5}{} {:<24} {:<10} {:>24} {:>24} {:>7}  {}{}\n", f.fit_id,
               f.fit_id == released ? "*" : " ", f.created_utc,
               fmt::format("{}", fmt::join(f.runs, ",")), pm(f, "k1"), pm(f, "k0"),
               f.std_ratio ? fmt::format("{:.3f}", *f.std_ratio) : "undef",
               verdict_text(verdict_of(f)), f.station.empty() ? "" : "  station " + f.station);
  }
  print_releases(releases);
  for (const auto& s : h.scatter) {
    if (s.n < 2) {
      fmt::print("  {} scatter: {} calibration(s) with terms {}: nothing to compare\n",
                 s.coefficient, s.n, h.terms);
      continue;
    }
    fmt::print("  {} scatter over {} calibrations: std {:.2e}, RMS SE {:.2e}, Birge ratio {}\n",
               s.coefficient, s.n, *s.sample_std, s.rms_se.value_or(0),
               s.birge_ratio ? fmt::format("{:.2f}", *s.birge_ratio) : "undefined");
  }
  for (const auto& f : h.flags) {
    fmt::print(
        "  DRIFT: fit {} {} moved {:.3e} from fit {} (zeta {:.1f}, limit {:.0f}): drift or "
        "a damaged gyro\n",
        f.fit_id, f.coefficient, f.delta, f.previous_fit_id, f.zeta, kDriftZetaLimit);
  }
  if (h.flags.empty() && h.calibrations.size() > 1)
    fmt::print("  no calibration moved more than {:.0f} combined standard errors\n",
               kDriftZetaLimit);
}

json acceptance_row_json(const AcceptanceRow& r) {
  const json& v = r.figures.contains("verdict") ? r.figures["verdict"] : json();
  return {{"run_id", r.run_id},
          {"computed_utc", r.computed_utc},
          {"sf_pulse_per_arcsec", opt(r.sf_pulse_per_arcsec)},
          {"sf_se_pulse_per_arcsec", opt(r.sf_se_pulse_per_arcsec)},
          {"sf_temp_c", opt(r.sf_temp_c)},
          {"tc_ppm_per_c", opt(r.tc_ppm_per_c)},
          {"tc_se_ppm_per_c", opt(r.tc_se_ppm_per_c)},
          {"nonlinearity_max_ppm_fs", opt(r.nonlinearity_max_ppm_fs)},
          {"asymmetry_ppm", opt(r.asymmetry_ppm)},
          {"tilt_mrad", opt(r.tilt_mrad)},
          {"turn_on_repeatability_dph", opt(r.turn_on_repeatability_dph)},
          {"max_warmup_s", opt(r.max_warmup_s)},
          {"turn_on_steps", turn_on_steps_json(r.turn_on_steps)},
          {"verdict", v}};
}

/// "acceptance": each run's stored figures; "scale_factor_drift": K's (and TC's) change from
/// run to run with its combined SE. Both null with --pg on a fleet server older than schema 6.
json acceptance_history_json(const std::optional<std::vector<AcceptanceRow>>& rows) {
  if (!rows) return {{"acceptance", nullptr}, {"scale_factor_drift", nullptr}};
  json runs = json::array(), drift = json::array();
  for (const auto& r : *rows) runs.push_back(acceptance_row_json(r));
  for (const auto& d : scale_factor_drift(*rows))
    drift.push_back({{"run_id", d.run_id},
                     {"previous_run_id", d.previous_run_id},
                     {"delta_ppm", d.delta_ppm},
                     {"se_ppm", d.se_ppm},
                     {"zeta", opt(d.zeta)},
                     {"tc_delta_ppm_per_c", opt(d.tc_delta_ppm_per_c)},
                     {"tc_se_ppm_per_c", opt(d.tc_se_ppm_per_c)},
                     {"tc_zeta", opt(d.tc_zeta)},
                     {"temp_gap_c", opt(d.temp_gap_c)},
                     {"drift", d.drift}});
  return {{"acceptance", runs}, {"scale_factor_drift", drift}};
}

/// "PASS, 13 limits (GX-200)", or "not judged" where the part had no acceptance limits.
std::string row_verdict_text(const AcceptanceRow& r) {
  if (!r.figures.contains("verdict")) return "not judged";
  return fmt::format("{} ({})", acceptance_verdict_text(r.figures["verdict"]),
                     r.part_number.value_or("?"));
}

std::string pm_text(const std::optional<double>& v, const std::optional<double>& se,
                    const char* format) {
  if (!v) return "-";
  return fmt::format(fmt::runtime(format), *v) + (se ? fmt::format(" +- {:.1e}", *se) : "");
}

void print_drift(const ScaleFactorDrift& d) {
  std::string tc;
  if (d.tc_delta_ppm_per_c)
    tc = fmt::format(", TC {:+.3f} +- {:.3f} ppm/C", *d.tc_delta_ppm_per_c, *d.tc_se_ppm_per_c);
  fmt::print("  scale factor run {} from run {}: {:+.1f} +- {:.1f} ppm (zeta {}){}{}{}\n", d.run_id,
             d.previous_run_id, d.delta_ppm, d.se_ppm,
             d.zeta ? fmt::format("{:.1f}", *d.zeta) : "undefined", tc,
             d.temp_gap_c ? fmt::format(" (K held {:+.1f} C apart)", *d.temp_gap_c) : "",
             d.drift
                 ? fmt::format(": DRIFT beyond {:.0f} combined standard errors", kDriftZetaLimit)
                 : "");
}

/// Each power_cycles step of a run: its turn-on sigma with its interval and longest warm-up.
void print_turn_on_steps(const AcceptanceRow& r) {
  for (const auto& t : r.turn_on_steps) {
    const std::string name = turn_on_step_name(t);
    const std::string where =
        fmt::format("  run {} turn-on{}{}", r.run_id, name.empty() ? "" : " ", name);
    fmt::print("{}: {}\n", where, turn_on_step_text(t));
  }
}

void print_acceptance_history(const std::optional<std::vector<AcceptanceRow>>& rows) {
  if (!rows) {
    fmt::print(
        "  acceptance figures: the fleet database has no acceptance table yet (migrate it with "
        "`station sync --init`)\n");
    return;
  }
  if (rows->empty()) return;
  fmt::print("  {:>6} {:>28} {:>7} {:>24}  acceptance verdict\n", "run", "K pulse/arcsec", "at C",
             "TC ppm/C");
  for (const auto& r : *rows)
    fmt::print("  {:>6} {:>28} {:>7} {:>24}  {}\n", r.run_id,
               pm_text(r.sf_pulse_per_arcsec, r.sf_se_pulse_per_arcsec, "{:.7f}"),
               r.sf_temp_c ? fmt::format("{:.1f}", *r.sf_temp_c) : "-",
               pm_text(r.tc_ppm_per_c, r.tc_se_ppm_per_c, "{:+.3f}"), row_verdict_text(r));
  for (const auto& r : *rows) print_turn_on_steps(r);
  for (const auto& d : scale_factor_drift(*rows)) print_drift(d);
}

/// What history reads: the runs, fits and releases, and the acceptance figures (empty with
/// --pg on a fleet server older than schema 6).
struct HistoryRead {
  fleet::FleetSerialHistory h;
  std::optional<std::vector<AcceptanceRow>> acceptance;
};

HistoryRead read_history(const HistoryOptions& o) {
  if (!o.pg.empty()) {
    if (auto why = pg_url_problem(o.pg)) throw InputError(fmt::format("--pg: {}", *why));
    fleet::PgConnection pg({o.pg, {}});
    return {fleet::fleet_serial_history(pg, o.serial),
            fleet::fleet_acceptance_rows_of_serial(pg, o.serial)};
  }
  Store store(o.db, OpenMode::read_only);
  HistoryRead r{
      {serial_runs(store, o.serial), serial_fits(store, o.serial), releases_of(store, o.serial)},
      acceptance_rows_of_serial(store, o.serial)};
  store.db().check_unchanged();
  return r;
}

void run_history(const HistoryOptions& o) {
  if (o.db.empty() == o.pg.empty()) throw InputError("give one of --db DB or --pg URL");
  const auto [got, acceptance] = read_history(o);
  const auto& [runs, fits, releases] = got;
  if (runs.empty() && fits.empty())
    throw InputError(
        fmt::format("{}: no run or fit of serial '{}'", o.pg.empty() ? o.db : o.pg, o.serial));
  const auto h = serial_history_stats(fits);
  if (o.json) {
    json j = history_json(o.serial, runs, fits, h, releases);
    j.update(acceptance_history_json(acceptance));
    std::cout << j.dump(2) << '\n';
    return;
  }
  print_history(o.serial, runs, fits, h, releases);
  print_acceptance_history(acceptance);
}

}  // namespace

void add_history_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<HistoryOptions>();
  auto* cmd = app.add_subcommand(
      "history", "Every run and fit of one gyro, the scatter of its coefficients and drift");
  cmd->footer(exit_status_footer({{0, "the history was printed"}}));
  cmd->add_option("--db", o->db, "SQLite database (opened read-only)");
  cmd->add_option("--pg", o->pg,
                  "the fleet's PostgreSQL (libpq URL): every station's calibrations of the gyro");
  cmd->add_option("--serial", o->serial, "gyro serial number")->required();
  cmd->add_flag("--json", o->json, "print JSON");
  cmd->callback([o, &status] {
    run_history(*o);
    status.exit_code = 0;
  });
}

}  // namespace station
