// `station adev`: overlapping Allan deviation of one CSV column, with the IEEE 952 noise terms.
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <span>

#include "compensation/allan.hpp"
#include "compensation/limits.hpp"
#include "station/cli/commands.hpp"
#include "station/cli/csv_table.hpp"
#include "station/cli/exit_status.hpp"
#include "station/cli/number_options.hpp"

namespace station {
namespace {

namespace sc = station::compensation;

struct AdevOptions {
  std::string file, col;
  double rate_hz = 1.0;
  std::string taus = "octave";
  std::string kind = "adev";  ///< adev or hdev
  bool json = false;
};

/// Averaging factors from "octave", "decade", "all" or a list of tau values in seconds, each a
/// whole multiple of the sample period that the n samples can average over (n - 2m + 1 >= 2).
std::vector<std::size_t> factors_from(const AdevOptions& o, std::size_t n) {
  if (auto spacing = sc::tau_spacing_from_name(o.taus)) return sc::tau_factors(n, *spacing);
  std::vector<std::size_t> ms;
  const std::size_t m_max = n < 3 ? 0 : (n - 1) / 2;
  std::size_t start = 0;
  while (start <= o.taus.size()) {
    const auto comma = o.taus.find(',', start);
    const std::string word =
        o.taus.substr(start, comma == std::string::npos ? comma : comma - start);
    double tau_s = 0;
    const auto [ptr, ec] = std::from_chars(word.data(), word.data() + word.size(), tau_s);
    if (word.empty() || ec != std::errc{} || ptr != word.data() + word.size() ||
        !std::isfinite(tau_s)) {
      throw InputError(fmt::format("--taus: '{}' is not octave, decade, all or a number", word));
    }
    const double m = tau_s * o.rate_hz;
    if (!(m >= 1) || std::abs(m - std::round(m)) > 1e-9) {
      throw InputError(
          fmt::format("--taus: {} s is not a whole multiple of 1/{} s", word, o.rate_hz));
    }
    if (m > static_cast<double>(m_max)) {
      throw InputError(
          fmt::format("--taus: {} s is longer than {} samples can average over", word, n));
    }
    ms.push_back(static_cast<std::size_t>(std::llround(m)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return ms;
}

nlohmann::json noise_json(const sc::NoiseTerms& nt) {
  auto opt = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json();
  };
  return {{"method", "weighted fit of the Allan variance (IEEE 952 Table C.2)"},
          {"quantization_arcsec", opt(nt.quantization_arcsec)},
          {"quantization_se_arcsec", opt(nt.quantization_se)},
          {"angle_random_walk_deg_rth", opt(nt.angle_random_walk_deg_rth)},
          {"angle_random_walk_se_deg_rth", opt(nt.angle_random_walk_se)},
          {"bias_instability_dph", opt(nt.bias_instability_dph)},
          {"bias_instability_se_dph", opt(nt.bias_instability_se)},
          {"bias_instability_tau_s", opt(nt.bias_instability_tau_s)},
          {"rate_random_walk_dph_rth", opt(nt.rate_random_walk_dph_rth)},
          {"rate_random_walk_se_dph_rth", opt(nt.rate_random_walk_se)},
          {"chi2_per_dof", opt(nt.fit_chi2_per_dof)}};
}

/// The deviation curve the options ask for; bad data is one line naming the file and column.
std::vector<sc::AdevPoint> curve_of(const AdevOptions& o, std::span<const double> rate) {
  const auto ms = factors_from(o, rate.size());
  try {
    return sc::overlapping_adev(
        rate, o.rate_hz, ms, 0.683,
        o.kind == "hdev" ? sc::DeviationKind::hdev : sc::DeviationKind::adev);
  } catch (const sc::DataError& e) {
    throw InputError(fmt::format("{}: column '{}': {}", o.file, o.col, e.what()));
  }
}

/// One object per tau: the point, its interval, the noise it assumes and how that was found
/// (`alpha_identified` is kept for readers of the earlier output: noise_id is not "none").
nlohmann::json rows_json(const std::vector<sc::AdevPoint>& pts) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& p : pts) {
    rows.push_back({{"tau_s", p.tau_s},
                    {"m", p.m},
                    {"adev", p.adev},
                    {"ci_low", p.ci_low},
                    {"ci_high", p.ci_high},
                    {"n", p.n},
                    {"alpha", p.alpha},
                    {"noise_id", std::string(sc::noise_id_method_name(p.noise_id))},
                    {"alpha_identified", p.noise_id != sc::NoiseIdMethod::none},
                    {"edf", p.edf}});
  }
  return rows;
}

/// The table's mark after alpha: blank for the lag-1 method, b for the B1 ratio, * carried.
const char* method_mark(sc::NoiseIdMethod method) {
  switch (method) {
    case sc::NoiseIdMethod::lag1:
      return " ";
    case sc::NoiseIdMethod::b1:
      return "b";
    case sc::NoiseIdMethod::none:
      break;
  }
  return "*";
}

void print_table(const AdevOptions& o, std::size_t n, const std::vector<sc::AdevPoint>& pts,
                 const sc::NoiseTerms& nt) {
  const bool h = o.kind == "hdev";
  fmt::print(
      "{}: column '{}', {} samples at {:g} Hz, overlapping {} (IEEE 952 / NIST SP 1065); 68.3 % "
      "intervals with Greenhall's edf for the noise identified at each tau (alpha: +2 white PM, "
      "0 white FM = ARW, -1 flicker FM = bias instability, -2 random-walk FM = RRW; unmarked: "
      "lag-1 autocorrelation, b: B1 ratio (8-29 averages), *: carried from a shorter tau)\n\n",
      o.file, o.col, n, o.rate_hz, h ? "Hadamard deviation" : "Allan deviation");
  // Units in the headings: tau in s, the deviation and its interval in the column's unit
  // (deg/h, as the noise terms below assume).
  fmt::print("  {:>12} {:>9} {:>15} {:>15} {:>15} {:>9} {:>6} {:>8}\n", "tau (s)", "m",
             h ? "hdev (deg/h)" : "adev (deg/h)", "ci_low (deg/h)", "ci_high (deg/h)", "n", "alpha",
             "edf");
  for (const auto& p : pts) {
    fmt::print("  {:>12g} {:>9} {:>15.5e} {:>15.5e} {:>15.5e} {:>9} {:>5}{} {:>8.1f}\n", p.tau_s,
               p.m, p.adev, p.ci_low, p.ci_high, p.n, p.alpha, method_mark(p.noise_id), p.edf);
  }
  auto line = [](const char* what, const std::optional<double>& v, const std::optional<double>& se,
                 const char* unit) {
    if (v)
      fmt::print("  {:<26} {:.4e} +- {:.1e} {}\n", what, *v, se.value_or(NAN), unit);
    else
      fmt::print("  {:<26} not in fit\n", what);
  };
  fmt::print(
      "\nnoise terms, weighted fit of the whole Allan-variance curve (IEEE 952 Table C.2; units "
      "assume the column is in deg/h; chi2/dof {:.2f}):\n",
      nt.fit_chi2_per_dof.value_or(NAN));
  line("quantization Q", nt.quantization_arcsec, nt.quantization_se, "arcsec");
  line("angle random walk N", nt.angle_random_walk_deg_rth, nt.angle_random_walk_se, "deg/sqrt(h)");
  line("bias instability B", nt.bias_instability_dph, nt.bias_instability_se, "deg/h");
  line("rate random walk K", nt.rate_random_walk_dph_rth, nt.rate_random_walk_se, "deg/h/sqrt(h)");
}

}  // namespace

void add_adev_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<AdevOptions>();
  auto* cmd = app.add_subcommand("adev", "Overlapping Allan deviation of a CSV column");
  cmd->footer(exit_status_footer({{0, "the deviation and noise terms were printed"}}));
  cmd->add_option("file", o->file, "CSV with a header row")->required();
  cmd->add_option("--col", o->col, "column holding the rate series")->required();
  cmd->add_option("--rate-hz", o->rate_hz, "sample rate, Hz")
      ->capture_default_str()
      ->check(finite_positive(1e9, "Hz"));
  cmd->add_option("--taus", o->taus, "octave|decade|all|LIST of tau in s")->capture_default_str();
  cmd->add_option("--kind", o->kind,
                  "adev (Allan) or hdev (Hadamard: insensitive to a linear rate drift)")
      ->check(CLI::IsMember({"adev", "hdev"}))
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->callback([o, &status] {
    const CsvColumns csv = read_csv_columns(o->file, {o->col});
    const auto& rate = csv[0];
    if (rate.size() < 3) {
      throw InputError(fmt::format("{}: {} samples; ADEV needs at least 3", o->file, rate.size()));
    }
    const auto pts = curve_of(*o, rate);
    const auto nt = sc::fit_noise_terms(pts);
    if (o->json) {
      std::cout << nlohmann::json{{"kind", o->kind},
                                  {"rows", rows_json(pts)},
                                  {"noise", noise_json(nt)}}
                       .dump(2)
                << '\n';
    } else {
      print_table(*o, rate.size(), pts, nt);
    }
    status.exit_code = 0;
  });
}

}  // namespace station
