// `station analyze`: the engineer's offline tool and batch calibration from another rig's CSV.
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "compensation/binning.hpp"
#include "compensation/earth_rate.hpp"
#include "compensation/fit.hpp"
#include "compensation/limits.hpp"
#include "station/cli/commands.hpp"
#include "station/cli/csv_table.hpp"
#include "station/cli/exit_status.hpp"
#include "station/cli/number_options.hpp"
#include "station/store/fit_json.hpp"

namespace station {
namespace {

namespace sc = station::compensation;

/// Widest bin accepted, s (116 days): wider than any record this station makes.
constexpr double kMaxBinS = 1e7;

struct AnalyzeOptions {
  std::string file;
  std::string time_col = "time_s", rate_col = "rate_dph", temp_col = "temp_c";
  std::string grad_col, temp2_col;
  double bin_s = sc::kPaperBinS;
  double ref_temp_c = 25.0;
  std::string terms = "dT,gradT";
  std::optional<double> earth_rate_dph, latitude_deg;
  std::string axis = "up";
  bool json = false;
  /// The part's noise (--arw, --bias-instability, --rrw, --noise-trust): a prior on the error
  /// model, in the part file's units (compensation/noise_prior.hpp).
  std::optional<double> arw_deg_rt_h, bias_instability_dph, rrw_dph_rt_h;
  double noise_trust = sc::NoisePrior{}.trust_factor;
  bool noise_trust_given = false;
};

/// The prior the options give; empty when they give no term.
std::optional<sc::NoisePrior> noise_prior_of(const AnalyzeOptions& o) {
  sc::NoisePrior p{o.arw_deg_rt_h, o.bias_instability_dph, o.rrw_dph_rt_h, o.noise_trust};
  if (!p.empty()) return p;
  if (o.noise_trust_given)
    throw InputError(
        "--noise-trust: give the part's noise too (--arw, --bias-instability or --rrw)");
  return std::nullopt;
}

/// Earth rate from the options: explicit value, or latitude + axis ("up", ..., "heading:DEG").
double earth_rate_from(const AnalyzeOptions& o) {
  if (o.earth_rate_dph) return *o.earth_rate_dph;
  if (!o.latitude_deg) {
    // Fitted into B0, Earth rate would make a bias of several deg/h that is not the gyro's.
    throw InputError(
        "give the site's --latitude DEG (with --axis, default up) to remove Earth rate, or "
        "--earth-rate-dph 0 when the rates have none");
  }
  sc::EnuAxis axis;
  try {
    axis = sc::parse_axis(o.axis);
  } catch (const sc::DataError& e) {
    throw InputError(fmt::format("--axis: {}", e.what()));
  }
  return sc::earth_rate_along_axis_dph(*o.latitude_deg, axis);
}

/// Every value within its physical bound (compensation/limits.hpp), named by file, line, column.
void check_columns(const CsvColumns& csv, bool grad_is_difference) {
  require_within(csv, 1, sc::rate_problem);
  require_within(csv, 2, sc::temp_problem);
  if (csv.columns.size() > 3) {
    require_within(csv, 3, grad_is_difference ? sc::temp_diff_problem : sc::temp_problem);
  }
}

struct Analysis {
  std::size_t samples = 0, bins_used = 0, bins_flagged = 0;
  double earth_rate_dph = 0;
  sc::FitResult fit;
  sc::Evaluation eval;
  std::vector<std::string> warnings;
};

Analysis analyze(const AnalyzeOptions& o) {
  std::vector<sc::Term> terms;
  try {
    terms = sc::parse_terms(o.terms);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("--terms: {}", e.what()));
  }
  std::vector<std::string> cols{o.time_col, o.rate_col, o.temp_col};
  std::string grad_col = o.grad_col, temp2_col = o.temp2_col;
  const bool wants_grad = std::any_of(terms.begin(), terms.end(), [](sc::Term t) {
    return t == sc::Term::gradT || t == sc::Term::gradTdT;
  });
  if (wants_grad && grad_col.empty() && temp2_col.empty()) {
    // The documented columns (README, "CSV input"): grad_c, else temp2_c, when the file has one.
    const auto header = read_csv_header(o.file);
    const auto has = [&](const char* n) {
      return std::find(header.begin(), header.end(), n) != header.end();
    };
    if (has("grad_c"))
      grad_col = "grad_c";
    else if (has("temp2_c"))
      temp2_col = "temp2_c";
  }
  const std::string grad_source = !grad_col.empty() ? grad_col : temp2_col;
  if (!grad_source.empty()) cols.push_back(grad_source);
  if (wants_grad && grad_source.empty()) {
    throw InputError(
        "term gradT needs a gradient: the file has no grad_c or temp2_c column; name one with "
        "--grad-col NAME or --temp2-col NAME");
  }
  const CsvColumns csv = read_csv_columns(o.file, cols);
  require_increasing(csv, 0);
  check_columns(csv, !grad_col.empty());
  std::vector<double> grad;
  if (!grad_source.empty()) {
    grad = csv[3];
    // With two sensors the gradient is temp2 - temp, sample by sample.
    if (grad_col.empty()) {
      for (std::size_t i = 0; i < grad.size(); ++i) grad[i] -= csv[2][i];
    }
  }
  Analysis a;
  a.samples = csv.lines.size();
  a.earth_rate_dph = earth_rate_from(o);
  sc::BinConfig bin_cfg;
  bin_cfg.width_s = o.bin_s;
  try {
    const auto bins = sc::make_bins({csv[0], csv[1], csv[2], grad, {}}, bin_cfg);
    const sc::ModelData data = sc::model_data_from_bins(bins, a.earth_rate_dph);
    a.bins_used = data.bias_dph.size();
    a.bins_flagged = bins.size() - a.bins_used;
    a.fit = sc::fit_model(data.view(), sc::ModelSpec{terms, o.ref_temp_c, noise_prior_of(o)});
    a.eval = sc::evaluate(data.bias_dph, sc::compensate(a.fit, data.view()), a.earth_rate_dph);
  } catch (const sc::DataError& e) {
    throw InputError(fmt::format("{}: {}", o.file, e.what()));
  }
  a.warnings.insert(a.warnings.end(), a.fit.warnings.begin(), a.fit.warnings.end());
  return a;
}

nlohmann::json to_json(const Analysis& a) {
  nlohmann::json j = fit_summary_json_with_diagnostics(a.fit, a.eval);
  j["bins_flagged"] = a.bins_flagged;
  j["samples"] = a.samples;
  j["earth_rate_dph"] = a.earth_rate_dph;
  j["warnings"] = a.warnings;  // the fit's and the command's own
  return j;
}

void print_table(const AnalyzeOptions& o, const Analysis& a) {
  fmt::print(
      "{}: {} samples, {} bins of {:g} s used, {} flagged; Earth rate {:.5f} deg/h removed\n",
      o.file, a.samples, a.bins_used, o.bin_s, a.bins_flagged, a.earth_rate_dph);
  fmt::print(
      "model: B = B0{}, T_ref = {:g} C\n\n",
      [&] {
        std::string s;
        for (std::size_t i = 1; i < a.fit.names.size(); ++i) {
          s += fmt::format(" + {}*{}", a.fit.names[i],
                           sc::term_option_name(a.fit.spec.terms[i - 1]));
        }
        return s;
      }(),
      o.ref_temp_c);
  fmt::print("  {:<4} {:>14} {:>12} {:>14} {:>7}  {}\n", "term", "value", "std error", "Newey-West",
             "VIF", "unit");
  for (std::size_t i = 0; i < a.fit.names.size(); ++i) {
    const std::string vif =
        i == 0 || i > a.fit.vif.size() ? "-" : fmt::format("{:.1f}", a.fit.vif[i - 1]);
    fmt::print("  {:<4} {:>14.6e} {:>12.3e} {:>14.3e} {:>7}  {}\n", a.fit.names[i],
               a.fit.coefficients[i], a.fit.std_errors[i], a.fit.std_errors_hac[i], vif,
               sc::coefficient_unit(a.fit.names[i]));
  }
  fmt::print("\n{}\n", evaluation_text(a.eval));
  fmt::print("R^2 {:.4f}, residual RMS {:.5f} deg/h, condition number {:.1f}\n", a.fit.r2,
             a.fit.residual_rms_dph, a.fit.condition_number);
  fmt::print("{}\n", walk_text(a.fit));
  for (const auto& w : a.warnings) fmt::print("warning: {}\n", w);
}

/// The part's noise (a prior on the error model, compensation/noise_prior.hpp).
void add_noise_options(CLI::App* cmd, AnalyzeOptions& o) {
  cmd->add_option("--arw", o.arw_deg_rt_h,
                  "the part's angle random walk N, deg/sqrt(h): a prior on the error model")
      ->check(finite_positive(sc::kMaxNoiseTerm, "deg/sqrt(h)"));
  cmd->add_option("--bias-instability", o.bias_instability_dph,
                  "the part's bias instability B, deg/h: a prior on the error model")
      ->check(finite_positive(sc::kMaxNoiseTerm, "deg/h"));
  cmd->add_option("--rrw", o.rrw_dph_rt_h,
                  "the part's rate random walk K, deg/h/sqrt(h) (0: none): a prior on the error "
                  "model")
      ->check(finite_within(0.0, sc::kMaxNoiseTerm, "deg/h/sqrt(h)"));
  cmd->add_option("--noise-trust", o.noise_trust,
                  "how far to trust the part's noise: the true value within x/ this factor")
      ->capture_default_str()
      ->check(finite_within(sc::kMinNoiseTrust, sc::kMaxNoiseTrust, ""));
}

}  // namespace

void add_analyze_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<AnalyzeOptions>();
  auto* cmd =
      app.add_subcommand("analyze", "Bin, fit and evaluate the thermal bias model of a CSV");
  cmd->footer(exit_status_footer({{0, "the model was fitted and evaluated"}}));
  cmd->add_option("file", o->file, "CSV with a header row")->required();
  cmd->add_option("--time-col", o->time_col, "time column, s")->capture_default_str();
  cmd->add_option("--rate-col", o->rate_col, "gyro rate column, deg/h")->capture_default_str();
  cmd->add_option("--temp-col", o->temp_col, "gyro temperature column, C")->capture_default_str();
  auto* g =
      cmd->add_option("--grad-col", o->grad_col,
                      "temperature-gradient column, C (default: grad_c when the file has it)");
  cmd->add_option(
         "--temp2-col", o->temp2_col,
         "second sensor column: gradient = temp2 - temp (default: temp2_c when the file has it)")
      ->excludes(g);
  cmd->add_option("--bin-s", o->bin_s, "bin width, s")
      ->capture_default_str()
      ->check(finite_positive(kMaxBinS, "s"));
  cmd->add_option("--ref-temp-c", o->ref_temp_c, "reference temperature T_ref, C")
      ->capture_default_str()
      ->check(finite_within(sc::kMinTempC, sc::kMaxTempC, "C"));
  cmd->add_option("--terms", o->terms, "dT,dT2,dT3,dT4,gradT,dTdt,gradTdT (B0 always)")
      ->capture_default_str();
  // A component of the Earth rate cannot exceed the rate itself; 0.1 % slack for a user's
  // rounding of 15.041 deg/h.
  auto* er =
      cmd->add_option("--earth-rate-dph", o->earth_rate_dph, "Earth rate along the axis")
          ->check(finite_within(-1.001 * sc::kEarthRateDph, 1.001 * sc::kEarthRateDph, "deg/h"));
  cmd->add_option("--latitude", o->latitude_deg,
                  "site latitude, deg (this or --earth-rate-dph is required)")
      ->excludes(er)
      ->check(finite_within(-90.0, 90.0, "deg"));
  cmd->add_option("--axis", o->axis, "up|down|north|south|east|west|heading:DEG")
      ->capture_default_str();
  add_noise_options(cmd, *o);
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->callback([o, cmd, &status] {
    o->noise_trust_given = cmd->count("--noise-trust") > 0;
    const Analysis a = analyze(*o);
    if (o->json) {
      std::cout << to_json(a).dump(2) << '\n';
    } else {
      print_table(*o, a);
    }
    status.exit_code = 0;
  });
}

}  // namespace station
