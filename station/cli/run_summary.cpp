// The end summary of a run (run_summary.hpp).
#include "station/cli/run_summary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>

#include "station/acceptance/acceptance_json.hpp"
#include "station/acceptance/acceptance_record.hpp"
#include "station/parts/run_results.hpp"
#include "station/parts/verdict.hpp"
#include "station/store/acceptance_results.hpp"

namespace station {
namespace {

using nlohmann::json;

/// A coefficient's cell: "-" where the fit has no such coefficient (a part's model may lack k1
/// or k0).
std::string cell(const json& j, const char* name, const char* format) {
  return j.contains(name) && j[name].is_number()
             ? fmt::format(fmt::runtime(format), j[name].get<double>())
             : std::string("-");
}

std::string ratio_text(const json& ratio) {
  return ratio.is_number() ? fmt::format("{:.3f}", ratio.get<double>()) : "undef";
}

void append_gyro(std::string& out, const json& g) {
  auto it = std::back_inserter(out);
  const std::string serial = g["serial"].get<std::string>();
  if (g.contains("true")) {
    const auto& t = g["true"];
    fmt::format_to(it, "{:<10} {:>4} {:>11.4e} {:>11.4e} {:>10.4e}\n", serial, "true",
                   t["B0"].get<double>(), t["k1"].get<double>(), t["k0"].get<double>());
  }
  if (!g.contains("fitted")) {
    fmt::format_to(it, "{:<10} {:>4} {}\n", serial, "", g.value("error", "no fit"));
    return;
  }
  const auto& f = g["fitted"];
  fmt::format_to(it, "{:<10} {:>4} {:>11} {:>11} {:>10}  {:>9.5f} {:>9.5f} {:>6}\n",
                 g.contains("true") ? "" : serial, "fit", cell(f, "B0", "{:.4e}"),
                 cell(f, "k1", "{:.4e}"), cell(f, "k0", "{:.4e}"),
                 g["std_before_dph"].get<double>(), g["std_after_dph"].get<double>(),
                 ratio_text(g["std_ratio"]));
  for (const auto& [label, key] : {std::pair{"+-", "std_errors"}, {"OLS", "std_errors_ols"}}) {
    const auto& e = g[key];
    fmt::format_to(it, "{:<10} {:>4} {:>11} {:>11} {:>10}\n", "", label, cell(e, "B0", "{:.1e}"),
                   cell(e, "k1", "{:.1e}"), cell(e, "k0", "{:.1e}"));
  }
  fmt::format_to(it, "{:<10} fit {}, model {}, {} bins: {}\n", "", g["fit_id"].get<long>(),
                 g.value("model", "?"), g.value("bins", 0L), g["verdict_text"].get<std::string>());
}

void append_verifications(std::string& out, const json& r) {
  if (!r.contains("verifications")) return;
  auto it = std::back_inserter(out);
  fmt::format_to(it, "\ncalibration run {}; released:", r["calibration_run"]["run_id"].get<long>());
  for (const auto& x : r["releases"])
    fmt::format_to(it, " {} (fit {}{})", x["serial"].get<std::string>(), x["fit_id"].get<long>(),
                   x["released"].get<bool>() ? "" : ", NOT released: verdict failed");
  fmt::format_to(
      it, "\nverification on run {} (the calibration applied to a run it was not fitted on):\n",
      r["run_id"].get<long>());
  fmt::format_to(it, "{:<10} {:>5} {:>13} {:>13} {:>6} {:>14}  verdict\n", "serial", "fit",
                 "std bef deg/h", "std aft deg/h", "ratio", "mean res deg/h");
  for (const auto& v : r["verifications"]) {
    if (v.contains("error")) {
      fmt::format_to(it, "{:<10} {:>5} {}\n", v["serial"].get<std::string>(),
                     v["fit_id"].get<long>(), v["error"].get<std::string>());
      continue;
    }
    const auto& verdict = v["verdict"];
    fmt::format_to(
        it, "{:<10} {:>5} {:>13.5f} {:>13.5f} {:>6} {:>+14.5f}  {}\n",
        v["serial"].get<std::string>(), v["fit_id"].get<long>(), v["std_before_dph"].get<double>(),
        v["std_after_dph"].get<double>(), ratio_text(v["ratio"]),
        v["mean_residual_dph"].get<double>(),
        verdict_text(verdict.is_null() ? std::nullopt : std::optional(verdict_from_json(verdict))));
  }
}

std::string header(const json& r) {
  if (r.contains("sim_s"))
    return fmt::format("run {} ({}): {:.1f} h simulated in {:.1f} s of wall time\n",
                       r["run_id"].get<long>(), r["state"].get<std::string>(),
                       r["sim_s"].get<double>() / 3600.0, r["wall_s"].get<double>());
  return fmt::format("run {} ({}): {:.2f} h, {} ticks\n", r["run_id"].get<long>(),
                     r["state"].get<std::string>(), r["t_s"].get<double>() / 3600.0,
                     r["ticks"].get<long>());
}

/// A word is quoted for a POSIX shell unless it is made only of characters no shell reads.
std::string shell_word(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                        "0123456789@%+=:,./_-") == std::string::npos)
    return s;
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// The run's acceptance figures as its end stored them; computed again only when none are stored
/// (the store failed at the end, logged then); empty without acceptance steps.
json summary_acceptance(Store& store, std::int64_t run_id,
                        const std::map<std::string, PartLimits>& part_limits) {
  json a = stored_acceptance_json(store, run_id);
  if (!a.empty()) return a;
  try {
    return judged_acceptance(store, run_id, part_limits);
  } catch (const std::exception&) {  // logged at the run's end; the thermal summary stands
    return json::array();
  }
}

}  // namespace

std::string run_summary_text(const json& r) {
  std::string out = header(r) + "\n";
  fmt::format_to(std::back_inserter(out), "{:<10} {:>4} {:>11} {:>11} {:>10}  {:>9} {:>9} {:>6}\n",
                 "serial", "", "B0 deg/h", "k1 deg/h/C", "k0 deg/h/C", "std deg/h", "after",
                 "ratio");
  for (const auto& g : r["gyros"]) append_gyro(out, g);
  const bool any_fit = std::any_of(r["gyros"].begin(), r["gyros"].end(),
                                   [](const json& g) { return g.contains("fitted"); });
  if (any_fit && r.contains("report")) out += "\nreport: " + r["report"].get<std::string>() + "\n";
  append_verifications(out, r);
  if (r.contains("acceptance")) out += acceptance_text(r["acceptance"]);
  return out;
}

std::string report_command(const std::string& db_path, std::int64_t run_id) {
  return fmt::format("station report --db {} --run {} --out {}", shell_word(db_path), run_id,
                     shell_word(fmt::format("report-run-{}", run_id)));
}

json rig_run_summary(Store& store, std::int64_t run_id, std::string_view state, double t_s,
                     std::int64_t ticks, const std::string& db_path,
                     const std::map<std::string, PartLimits>& part_limits) {
  json j{{"run_id", run_id},
         {"state", std::string(state)},
         {"t_s", t_s},
         {"ticks", ticks},
         {"gyros", run_results_json(store, run_id)},
         {"report", report_command(db_path, run_id)}};
  if (auto a = summary_acceptance(store, run_id, part_limits); !a.empty())
    j["acceptance"] = std::move(a);
  return j;
}

}  // namespace station
