// Judging fits: limits from the part file or the run's snapshot, the compensated 1 Hz record's
// ADEV floor, the verdict stored beside the fit.
#include "station/parts/judged_fit.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "compensation/adev_floor.hpp"
#include "station/store/fit_model_choice.hpp"
#include "station/store/fit_verdicts.hpp"
#include "station/store/serial_history.hpp"

namespace station {

namespace sc = station::compensation;

std::optional<PartLimits> limits_for(Store& store, const std::string& serial,
                                     const std::vector<std::int64_t>& runs,
                                     const PartChoice& choice) {
  std::string number = choice.part_number;
  std::optional<SlotPart> stored;
  if (number.empty()) {
    stored = find_run_part(store, serial, runs);
    if (!stored) return std::nullopt;
    number = stored->part_number;
  }
  if (choice.file != nullptr) {
    const auto it = choice.file->parts.find(number);
    if (it == choice.file->parts.end()) {
      throw InputError(fmt::format("{}: no part '{}' (serial '{}'{})", choice.file->path, number,
                                   serial, stored ? " names it in its run" : ""));
    }
    return it->second;
  }
  if (!stored) throw InputError(fmt::format("--part {}: give the part file with --parts", number));
  try {
    return part_limits_from_json(nlohmann::json::parse(stored->limits_json));
  } catch (const std::exception& e) {
    throw InputError(fmt::format("{}: serial '{}': {}", store.db().path(), serial, e.what()));
  }
}

std::vector<double> compensated_record_dph(Store& store, std::int64_t run_id,
                                           const std::string& serial, const sc::FitResult& fit) {
  for (const auto t : fit.spec.terms)
    if (t == sc::Term::dTdt || t == sc::Term::channel) return {};
  const sc::ModelData d = record_model_data(store, run_id, serial);
  if (d.bias_dph.empty()) return {};
  return sc::compensate(fit, d.view());
}

std::optional<double> fit_adev_floor_dph(Store& store, const SerialFit& f) {
  std::optional<double> worst;
  for (const auto run : f.runs) {
    const auto record = compensated_record_dph(store, run, f.serial, f.fit);
    const auto floor = sc::adev_floor(record, 1.0);  // the sequencer's 1 Hz tick
    if (floor && (!worst || floor->adev > *worst)) worst = floor->adev;
  }
  return worst;
}

JudgedFit judge_and_store(Store& store, SerialFit fit, const std::optional<PartLimits>& limits) {
  JudgedFit out{std::move(fit), std::nullopt, std::nullopt};
  if (!limits) return out;
  if (limits->max_adev_floor_dph) out.adev_floor_dph = fit_adev_floor_dph(store, out.fit);
  out.verdict = judge_fit(*limits, {out.fit.fit, out.fit.eval, out.adev_floor_dph});
  save_fit_verdict(store, out.fit.fit_id,
                   {limits->number, verdict_json(*out.verdict).dump(), out.adev_floor_dph});
  return out;
}

std::optional<Verdict> stored_verdict(Store& store, std::int64_t fit_id) {
  const auto v = load_fit_verdict(store, fit_id);
  if (!v.verdict_json) return std::nullopt;
  try {
    return verdict_from_json(nlohmann::json::parse(*v.verdict_json));
  } catch (const std::exception& e) {
    throw InputError(fmt::format("{}: fit {}: {}", store.db().path(), fit_id, e.what()));
  }
}

sc::ModelSpec part_model_spec(sc::ModelSpec given, const std::optional<PartLimits>& limits,
                              bool terms_given) {
  if (!limits) return given;
  if (limits->model && !terms_given) given.terms = sc::parse_terms(*limits->model);
  if (limits->noise) given.noise_prior = limits->noise;
  return given;
}

SerialFit fit_serial_for_part(Store& store, const std::string& serial,
                              const std::vector<std::int64_t>& runs, const sc::ModelSpec& given,
                              const std::optional<PartLimits>& limits, bool terms_given,
                              std::vector<std::string> warnings) {
  SerialFit f = fit_serial(store, serial, runs, part_model_spec(given, limits, terms_given),
                           std::move(warnings));
  if (limits && limits->model && !terms_given)
    save_fit_model_choice(store, f.fit_id, part_model_choice_json(limits->number, *limits->model));
  return f;
}

FitAllResult fit_all(Store& store, std::optional<std::int64_t> run_id, const sc::ModelSpec& spec,
                     const PartChoice& choice, bool terms_given) {
  std::vector<std::string> serials;
  if (run_id) {
    for (const auto& s : store.run_slots(*run_id)) serials.push_back(s.serial);
  } else {
    serials = all_serials(store);
  }
  FitAllResult out;
  out.fits.reserve(serials.size());
  // One transaction: a thousand fits commit once, and a part-file error stores none of them.
  Transaction tx(store.db());
  for (const auto& serial : serials) {
    const std::vector<std::int64_t> runs =
        run_id ? std::vector{*run_id} : store.runs_of_serial(serial);
    const auto limits = limits_for(store, serial, runs, choice);
    try {
      out.fits.push_back(judge_and_store(
          store, fit_serial_for_part(store, serial, runs, spec, limits, terms_given), limits));
    } catch (const InputError& e) {
      out.skipped.emplace_back(e.what());
    }
  }
  tx.commit();
  return out;
}

}  // namespace station
