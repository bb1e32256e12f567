// `station fit`: per serial, or every serial of a run; --cv adds leave-one-run-out prediction
// errors beside the in-sample std.
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "compensation/cross_validation.hpp"
#include "compensation/model_selection.hpp"
#include "station/acceptance/acceptance_json.hpp"
#include "station/acceptance/acceptance_record.hpp"
#include "station/cli/acceptance_beside.hpp"
#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/common/input_error.hpp"
#include "station/config/acceptance_steps.hpp"
#include "station/config/protocol.hpp"
#include "station/parts/deliverable_terms.hpp"
#include "station/parts/judged_fit.hpp"
#include "station/store/acceptance_results.hpp"
#include "station/store/calibration.hpp"
#include "station/store/fit_json.hpp"
#include "station/store/fit_model_choice.hpp"

namespace station {
namespace {

namespace sc = station::compensation;

struct FitOptions {
  std::string db, serial, terms = "dT,gradT", format = "json", parts, part;
  std::vector<std::int64_t> runs;
  std::optional<std::int64_t> run;
  double ref_temp_c = 25.0;
  bool all = false, json = false, cv = false, select = false;
  bool acceptance = false;   ///< --acceptance: the fitted runs' acceptance figures computed again
  bool terms_given = false;  ///< --terms was on the command line (a part's model gives way)
};

/// Leave-one-run-out cross-validation of one fit's model over its runs, or why there is none
/// (one run with bins, a fold with too few bins): the fit is stored already, so this never
/// throws.
struct CvOutcome {
  std::optional<sc::CrossValidation> cv;
  std::string why_not;
};

CvOutcome cross_validate(Store& store, const SerialFit& f) {
  const sc::ModelData data = store.model_data(f.serial, f.runs);
  const std::set<int> with_bins(data.segment.begin(), data.segment.end());
  if (with_bins.size() < 2)
    return {std::nullopt, fmt::format("needs two or more runs with complete bins ({} of runs {} "
                                      "have any)",
                                      with_bins.size(), fmt::join(f.runs, ","))};
  try {
    return {sc::leave_one_run_out(data.view(), f.fit.spec), {}};
  } catch (const std::exception& e) {
    return {std::nullopt, fmt::format("not possible: {}", e.what())};
  }
}

nlohmann::json cv_json(const CvOutcome& out, const std::vector<std::int64_t>& runs) {
  if (!out.cv) return {{"method", "leave-one-run-out"}, {"unavailable", out.why_not}};
  const auto& cv = out.cv;
  nlohmann::json held = nlohmann::json::array();
  for (const auto& h : cv->runs)
    held.push_back({{"run_id", runs.at(static_cast<std::size_t>(h.segment))},
                    {"bins", h.bins},
                    {"rms_dph", h.rms_dph},
                    {"std_dph", h.std_dph}});
  return {{"method", "leave-one-run-out"},
          {"held_out", held},
          {"pooled_rms_dph", cv->pooled_rms_dph},
          {"in_sample_rms_dph", cv->in_sample_rms_dph}};
}

void print_cv(const CvOutcome& out, const std::vector<std::int64_t>& runs) {
  if (!out.cv) {
    fmt::print("  cross-validation: {}\n", out.why_not);
    return;
  }
  const auto& cv = out.cv;
  fmt::print(
      "  leave-one-run-out: prediction RMS {:.5f} deg/h on held-out runs, in-sample {:.5f} "
      "deg/h ({:.2f}x)\n",
      cv->pooled_rms_dph, cv->in_sample_rms_dph, cv->pooled_rms_dph / cv->in_sample_rms_dph);
  for (const auto& h : cv->runs)
    fmt::print("    run {} held out: RMS {:.5f} deg/h, std {:.5f} deg/h over {} bins\n",
               runs.at(static_cast<std::size_t>(h.segment)), h.rms_dph, h.std_dph, h.bins);
}

/// Unit of each coefficient, for people and for the navigation computer.
std::string unit_of(const std::string& name) {
  return std::string(sc::coefficient_unit(name));
}

nlohmann::json fit_json(const JudgedFit& jf) {
  const SerialFit& f = jf.fit;
  nlohmann::json j = fit_summary_json_with_diagnostics(f.fit, f.eval);
  j["serial"] = f.serial;
  j["fit_id"] = f.fit_id;
  j["runs"] = f.runs;
  j["part_number"] = jf.verdict ? nlohmann::json(jf.verdict->part_number) : nlohmann::json();
  j["verdict"] = jf.verdict ? verdict_json(*jf.verdict) : nlohmann::json();
  j["adev_floor_dph"] = jf.adev_floor_dph ? nlohmann::json(*jf.adev_floor_dph) : nlohmann::json();
  return j;
}

/// `--acceptance`: the acceptance figures of every run the fits used (and of --run, fitted or
/// not; and of --serial's runs when it had nothing to fit) computed again and stored
/// (record_acceptance, the run's end's code path), judged against the part the fit is judged
/// against. Returns each run's figures.
std::map<std::int64_t, nlohmann::json> recompute_acceptance(Store& store,
                                                            const std::vector<JudgedFit>& fits,
                                                            std::set<std::int64_t> runs,
                                                            const PartChoice& choice) {
  for (const auto& f : fits) runs.insert(f.fit.runs.begin(), f.fit.runs.end());
  std::map<std::int64_t, nlohmann::json> out;
  for (const auto run : runs) {
    std::map<std::string, PartLimits> limits;
    for (const auto& slot : store.run_slots(run))
      if (auto l = limits_for(store, slot.serial, {run}, choice)) limits[slot.serial] = *l;
    out[run] = record_acceptance(store, run, limits);
  }
  return out;
}

/// `fit --all --acceptance` without --run: the runs whose stored protocol holds an acceptance
/// step (a run stored without its protocol text has none to compute; an unreadable one is said).
std::set<std::int64_t> runs_with_acceptance_steps(Store& store) {
  std::vector<std::int64_t> ids;
  auto st = store.db().prepare("SELECT DISTINCT run_id FROM run_slots ORDER BY run_id");
  while (st.step()) ids.push_back(st.column_int(0));
  std::set<std::int64_t> out;
  for (const auto id : ids) {
    const auto run = store.find_run(id);
    if (!run || run->protocol_text.empty()) continue;
    try {
      const auto p = parse_protocol(run->protocol_text, "run " + std::to_string(id));
      if (std::any_of(p.steps.begin(), p.steps.end(),
                      [](const Step& s) { return is_acceptance_step(s.kind); }))
        out.insert(id);
    } catch (const InputError& e) {
      fmt::print(stderr, "station: fit --acceptance: run {} skipped: {}\n", id, e.what());
    }
  }
  return out;
}

/// The recomputed figures of the serials no thermal fit was printed for (a run of acceptance
/// steps only has no bins): an array of their objects per run, for the text or the JSON.
std::map<std::int64_t, nlohmann::json> unfitted_acceptance(
    const std::map<std::int64_t, nlohmann::json>& figures, const std::vector<JudgedFit>& fits,
    const std::string& only_serial) {
  std::set<std::string> fitted;
  for (const auto& f : fits) fitted.insert(f.fit.serial);
  std::map<std::int64_t, nlohmann::json> out;
  for (const auto& [run, serials] : figures)
    for (const auto& s : serials) {
      const std::string serial = s.value("serial", "");
      if (fitted.contains(serial) || (!only_serial.empty() && serial != only_serial)) continue;
      if (!out.contains(run)) out[run] = nlohmann::json::array();
      out[run].push_back(s);
    }
  return out;
}

void print_fit(const JudgedFit& jf) {
  const SerialFit& f = jf.fit;
  fmt::print("{}: fit {} over runs {} ({} bins)\n", f.serial, f.fit_id, fmt::join(f.runs, ","),
             f.fit.n_points);
  for (std::size_t i = 0; i < f.fit.names.size(); ++i) {
    const std::string vif = i == 0 || i > f.fit.vif.size()
                                ? std::string()
                                : fmt::format("  VIF {:.1f}", f.fit.vif[i - 1]);
    fmt::print("  {:<3} {:>13.5e} +- {:.2e} {:<9} (OLS +- {:.2e}){}\n", f.fit.names[i],
               f.fit.coefficients[i], f.fit.std_errors[i], unit_of(f.fit.names[i]),
               f.fit.std_errors_ols[i], vif);
  }
  fmt::print("  {}\n", error_model_text(f.fit.error_model));
  fmt::print("  {}\n", walk_text(f.fit));
  fmt::print("  {}\n", evaluation_text(f.eval));
  for (const auto& w : f.fit.warnings) fmt::print("  warning: {}\n", w);
  if (jf.adev_floor_dph) fmt::print("  ADEV floor {:.5f} deg/h\n", *jf.adev_floor_dph);
  fmt::print("  verdict: {}\n", verdict_text(jf.verdict));
}

/// `--select`: the model chosen from `base` over the serial's runs (model_selection.hpp).
sc::ModelSelection select_for(Store& store, const std::string& serial,
                              const std::vector<std::int64_t>& runs, const sc::ModelSpec& base) {
  const sc::ModelData data = store.model_data(serial, runs);
  try {
    std::vector<sc::Term> every;
    for (int t = 0; t <= static_cast<int>(sc::Term::gradTdT); ++t)
      every.push_back(static_cast<sc::Term>(t));
    return sc::select_model(data.view(), base, deliverable_only(every));  // a release can carry
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: serial '{}', runs {}: --select: {}", store.db().path(),
                                 serial, fmt::join(runs, ","), e.what()));
  }
}

/// `--serial SN`: the part's model and noise, --select's choice, the fit judged and stored.
JudgedFit fit_one(Store& store, const FitOptions& o, const sc::ModelSpec& spec,
                  const PartChoice& choice) {
  const auto runs = o.runs.empty() ? store.runs_of_serial(o.serial) : o.runs;
  for (const auto id : o.runs)  // a fit "over runs 1,99" must not name a run that is not there
    if (!store.find_run(id)) throw InputError(fmt::format("{}: no run {} (--runs)", o.db, id));
  const auto limits = runs.empty() ? std::nullopt : limits_for(store, o.serial, runs, choice);
  std::optional<sc::ModelSelection> sel;
  if (o.select && !runs.empty())
    sel = select_for(store, o.serial, runs, part_model_spec(spec, limits, o.terms_given));
  // The fit, its verdict and how its model was chosen commit together, or none of them.
  Transaction tx(store.db());
  JudgedFit out =
      judge_and_store(store,
                      sel ? fit_serial(store, o.serial, runs, sel->chosen)
                          : fit_serial_for_part(store, o.serial, runs, spec, limits, o.terms_given),
                      limits);
  if (sel) save_fit_model_choice(store, out.fit.fit_id, model_selection_json(*sel));
  tx.commit();
  if (sel && !o.json) fmt::print("{}", model_selection_text(*sel));
  return out;
}

int run_fit(const FitOptions& o) {
  // A bad part file stops before the database is opened.
  std::optional<PartFile> parts;
  if (!o.parts.empty()) parts = load_part_file(o.parts);
  if (!o.part.empty() && !parts) throw InputError("fit: --part needs the part file (--parts)");
  if (parts && !o.part.empty() && !parts->parts.contains(o.part))
    throw InputError(fmt::format("{}: no part '{}' (--part)", o.parts, o.part));
  const PartChoice choice{parts ? &*parts : nullptr, o.part};
  if (!o.all && o.serial.empty()) throw InputError("fit: give --serial SN, or --all [--run ID]");
  Store store(o.db, OpenMode::existing);  // stores the fit; never creates a database
  const sc::ModelSpec spec{sc::parse_terms(o.terms), o.ref_temp_c};
  FitAllResult result;
  std::set<std::int64_t> acceptance_runs;  // --acceptance: runs computed whether fitted or not
  if (o.run) acceptance_runs.insert(*o.run);
  if (o.all) {
    if (o.run && !store.find_run(*o.run))
      throw InputError(fmt::format("{}: no run {}", o.db, *o.run));
    result = fit_all(store, o.run, spec, choice, o.terms_given);
    // Every run with acceptance steps: one of acceptance steps only has no fit to bring it.
    if (o.acceptance && !o.run) acceptance_runs.merge(runs_with_acceptance_steps(store));
  } else if (o.acceptance) {
    // A serial whose runs hold acceptance steps only has no bins: its figures are still shown.
    try {
      result.fits.push_back(fit_one(store, o, spec, choice));
    } catch (const InputError& e) {
      // Nothing to fit in runs that are there; an unknown serial or run stays the error it is.
      const auto runs = o.runs.empty() ? store.runs_of_serial(o.serial) : o.runs;
      if (runs.empty() ||
          std::any_of(runs.begin(), runs.end(), [&](auto id) { return !store.find_run(id); }))
        throw;
      result.skipped.push_back(e.what());
      acceptance_runs.insert(runs.begin(), runs.end());
    }
  } else {
    result.fits.push_back(fit_one(store, o, spec, choice));
  }
  // Serials with nothing to fit: one line each on stderr, and exit status 1 (the others stored).
  for (const auto& s : result.skipped) fmt::print(stderr, "station: fit skipped: {}\n", s);
  const auto& fits = result.fits;
  std::map<std::int64_t, nlohmann::json> unfitted;
  if (o.acceptance)
    unfitted = unfitted_acceptance(recompute_acceptance(store, fits, acceptance_runs, choice), fits,
                                   o.all ? std::string() : o.serial);
  const int status = result.skipped.empty() ? 0 : 1;
  if (o.json && (o.all || !fits.empty())) {
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& f : fits) {
      arr.push_back(fit_json(f));
      const auto choice = load_fit_model_choice(store, f.fit.fit_id);
      arr.back()["model_choice"] = choice ? *choice : nlohmann::json();
      arr.back()["acceptance"] = acceptance_beside_json(store, f.fit.serial, f.fit.runs);
      if (o.cv) arr.back()["cross_validation"] = cv_json(cross_validate(store, f.fit), f.fit.runs);
    }
    // Serials without a thermal fit whose acceptance figures were computed: one object each.
    for (const auto& [run, serials] : unfitted)
      for (const auto& a : serials)
        arr.push_back({{"serial", a.value("serial", "")},
                       {"fit_id", nullptr},
                       {"acceptance_run_id", run},
                       {"acceptance_figures", a}});
    std::cout << (o.all ? arr : arr[0]).dump(2) << '\n';
    return status;
  }
  if (o.json) {  // --serial --acceptance without a fit: its figures alone
    nlohmann::json figures = nlohmann::json::array();
    for (const auto& [run, serials] : unfitted)
      for (const auto& a : serials)
        figures.push_back({{"acceptance_run_id", run}, {"acceptance_figures", a}});
    std::cout << nlohmann::json{{"serial", o.serial}, {"fit_id", nullptr}, {"acceptance", figures}}
                     .dump(2)
              << '\n';
    return status;
  }
  for (const auto& f : fits) {
    print_fit(f);
    fmt::print("{}",
               acceptance_beside_text(acceptance_beside_json(store, f.fit.serial, f.fit.runs)));
    if (o.cv) print_cv(cross_validate(store, f.fit), f.fit.runs);
  }
  for (const auto& [run, serials] : unfitted) {
    fmt::print("run {}: no thermal fit for {} (no complete bins); its acceptance figures:", run,
               serials.size() == 1 ? "this serial" : "these serials");
    fmt::print("{}", acceptance_text(serials));
  }
  if (o.acceptance && fits.empty() && unfitted.empty())
    fmt::print("no thermal fit and no acceptance figures: the runs hold no acceptance step\n");
  return status;
}

}  // namespace

void add_fit_commands(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<FitOptions>();
  auto* fit = app.add_subcommand("fit", "Fit the thermal model per serial number from stored runs");
  fit->footer(exit_status_footer(
      {{0, "every serial was fitted and stored"},
       {1,
        "a serial had nothing to fit (one line each on stderr; the others are stored; with "
        "--acceptance its acceptance figures are still computed, stored and printed)"}}));
  fit->add_option("--db", o->db, "SQLite database")->required();
  auto* serial = fit->add_option("--serial", o->serial, "gyro serial number");
  fit->add_option("--runs", o->runs, "run ids (default: every run of the serial)")->delimiter(',');
  auto* all = fit->add_flag("--all", o->all,
                            "fit every serial of --run, or of the database over all its runs "
                            "(one transaction)")
                  ->excludes(serial);
  fit->add_option("--run", o->run, "run id for --all")->needs(all);
  fit->add_option("--parts", o->parts,
                  "part file: judge against it (default: the limits stored with the run)");
  fit->add_option("--part", o->part, "part number (default: the one the run's slot named)");
  fit->add_option("--terms", o->terms, "dT,dT2,dT3,dT4,gradT,dTdt,gradTdT (B0 always)")
      ->capture_default_str();
  fit->add_option("--ref-temp-c", o->ref_temp_c, "T_ref, C")->capture_default_str();
  fit->add_flag("--json", o->json, "print JSON");
  fit->add_flag("--select", o->select,
                "choose the model: from --terms, add the candidate terms (dT2, dT3, dTdt, "
                "gradTdT) one at a time while they help, by leave-one-run-out prediction error "
                "with two or more runs, by likelihood ratio with one; prints the models tried and "
                "stores the choice with the fit")
      ->excludes(all);
  fit->add_flag("--acceptance", o->acceptance,
                "compute the acceptance figures of the fitted runs again (an older run, another "
                "part file) and store them; without it the figures stored at each run's end are "
                "shown");
  fit->add_flag("--cv", o->cv,
                "leave-one-run-out cross-validation: prediction error on each held-out run "
                "beside the in-sample residual (two or more runs)");
  fit->callback([o, fit, &status] {
    o->terms_given = fit->count("--terms") > 0;
    status.exit_code = run_fit(*o);
  });
}

}  // namespace station
