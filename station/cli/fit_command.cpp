// `station fit` (per serial, or every serial of a run) and `station export` (coefficients for
// the navigation computer).
#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "station/cli/commands.hpp"
#include "station/common/input_error.hpp"
#include "station/store/calibration.hpp"
#include "station/store/fit_json.hpp"

namespace station {
namespace {

namespace sc = station::compensation;

struct FitOptions {
  std::string db, serial, terms = "dT,gradT", format = "json";
  std::vector<std::int64_t> runs;
  std::int64_t run = 0;
  double ref_temp_c = 25.0;
  bool all = false, json = false;
};

/// Unit of each coefficient, for people and for the navigation computer.
std::string unit_of(const std::string& name) {
  return std::string(sc::coefficient_unit(name));
}

nlohmann::json fit_json(const SerialFit& f) {
  nlohmann::json j = fit_summary_json(f.fit, f.eval);
  j["serial"] = f.serial;
  j["fit_id"] = f.fit_id;
  j["runs"] = f.runs;
  return j;
}

void print_fit(const SerialFit& f) {
  fmt::print("{}: fit {} over runs {} ({} bins)\n", f.serial, f.fit_id, fmt::join(f.runs, ","),
             f.fit.n_points);
  for (std::size_t i = 0; i < f.fit.names.size(); ++i) {
    fmt::print("  {:<3} {:>13.5e} +- {:.2e} {:<9} (OLS +- {:.2e})\n", f.fit.names[i],
               f.fit.coefficients[i], f.fit.std_errors[i], unit_of(f.fit.names[i]),
               f.fit.std_errors_ols[i]);
  }
  fmt::print("  {}\n", error_model_text(f.fit.error_model));
  fmt::print("  {}\n", evaluation_text(f.eval));
  for (const auto& w : f.fit.warnings) fmt::print("  warning: {}\n", w);
}

void run_fit(const FitOptions& o) {
  Store store(o.db, OpenMode::existing);  // stores the fit; never creates a database
  const sc::ModelSpec spec{sc::parse_terms(o.terms), o.ref_temp_c};
  std::vector<SerialFit> fits;
  if (o.all) {
    if (!store.find_run(o.run)) throw InputError(fmt::format("{}: no run {}", o.db, o.run));
    for (const auto& slot : store.run_slots(o.run))
      fits.push_back(fit_serial(store, slot.serial, {o.run}, spec));
  } else {
    if (o.serial.empty()) throw InputError("fit: give --serial SN, or --all --run ID");
    fits.push_back(fit_serial(store, o.serial, o.runs, spec));
  }
  if (o.json) {
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& f : fits) arr.push_back(fit_json(f));
    std::cout << (o.all ? arr : arr[0]).dump(2) << '\n';
    return;
  }
  for (const auto& f : fits) print_fit(f);
}

void run_export(const FitOptions& o) {
  Store store(o.db, OpenMode::read_only);
  const auto rec = store.latest_fit(o.serial);
  if (!rec)
    throw InputError(
        fmt::format("{}: no fit stored for serial '{}' (run `station fit` first)", o.db, o.serial));
  const auto& f = rec->fit;
  if (o.format == "csv") {
    fmt::print("serial,fit_id,term,value,std_error,std_error_ols,unit,ref_temp_c\n");
    for (std::size_t i = 0; i < f.names.size(); ++i) {
      const double ols = i < f.std_errors_ols.size() ? f.std_errors_ols[i] : NAN;
      fmt::print("{},{},{},{:.9e},{:.3e},{:.3e},{},{}\n", o.serial, rec->id, f.names[i],
                 f.coefficients[i], f.std_errors[i], ols, unit_of(f.names[i]), f.spec.ref_temp_c);
    }
    return;
  }
  nlohmann::json coef = nlohmann::json::object(), units = nlohmann::json::object();
  for (std::size_t i = 0; i < f.names.size(); ++i) {
    coef[f.names[i]] = f.coefficients[i];
    units[f.names[i]] = unit_of(f.names[i]);
  }
  const nlohmann::json j{
      {"serial", o.serial},
      {"fit_id", rec->id},
      {"created_utc", rec->created_utc},
      {"runs", rec->runs},
      {"terms", rec->terms},
      {"ref_temp_c", f.spec.ref_temp_c},
      {"model", "B = B0 + k1*dT + k2*dT^2 + ... + k0*gradT (dT = T - ref_temp_c, gradT = T2 - T1)"},
      {"coefficients", coef},
      {"std_errors", std_errors_json(f)},
      {"std_errors_ols", std_errors_ols_json(f)},
      {"error_model", error_model_json(f.error_model)},
      {"units", units},
      {"std_ratio", std_ratio_json(rec->eval)}};
  std::cout << j.dump(2) << '\n';
}

}  // namespace

void add_fit_commands(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<FitOptions>();
  auto* fit = app.add_subcommand("fit", "Fit the thermal model per serial number from stored runs");
  fit->add_option("--db", o->db, "SQLite database")->required();
  auto* serial = fit->add_option("--serial", o->serial, "gyro serial number");
  fit->add_option("--runs", o->runs, "run ids (default: every run of the serial)")->delimiter(',');
  auto* all = fit->add_flag("--all", o->all, "fit every serial of --run")->excludes(serial);
  fit->add_option("--run", o->run, "run id for --all")->needs(all);
  fit->add_option("--terms", o->terms, "dT,dT2,dT3,dT4,gradT,dTdt (B0 always)")
      ->capture_default_str();
  fit->add_option("--ref-temp-c", o->ref_temp_c, "T_ref, C")->capture_default_str();
  fit->add_flag("--json", o->json, "print JSON");
  fit->callback([o, &status] {
    run_fit(*o);
    status.exit_code = 0;
  });
  auto e = std::make_shared<FitOptions>();
  auto* exp = app.add_subcommand(
      "export", "Write a serial's latest coefficients for the navigation computer");
  exp->add_option("--db", e->db, "SQLite database")->required();
  exp->add_option("--serial", e->serial, "gyro serial number")->required();
  exp->add_option("--format", e->format, "json|csv")
      ->check(CLI::IsMember({"json", "csv"}))
      ->capture_default_str();
  exp->callback([e, &status] {
    run_export(*e);
    status.exit_code = 0;
  });
}

}  // namespace station
