// The report's two kinds of page: the run's index and one page per serial.
#include "station/report/report_pages.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "compensation/fit.hpp"
#include "station/report/report_model.hpp"
#include "station/store/fit_json.hpp"

namespace station::report {

using nlohmann::json;
namespace sc = station::compensation;

std::string num(double v, const char* spec) {
  return std::isfinite(v) ? fmt::format(fmt::runtime(spec), v) : "-";
}
std::string num(const std::optional<double>& v, const char* spec) {
  return v ? num(*v, spec) : "-";
}

std::string row(std::initializer_list<std::string> cells) {
  std::string out = "<tr>";
  for (const auto& c : cells) out += "<td>" + c + "</td>";
  return out + "</tr>\n";
}

std::string kv(const std::string& head, std::initializer_list<std::string> cells) {
  std::string out = "<tr><th scope=\"row\">" + head + "</th>";
  for (const auto& c : cells) out += "<td>" + c + "</td>";
  return out + "</tr>\n";
}

namespace {

/// A coefficient's unit as people write it: "deg/h/C^2" -> "°/h/°C²" (compensation::
/// coefficient_unit spells units in ASCII for files and JSON).
std::string unit_html(std::string_view ascii) {
  std::string out;
  for (std::size_t i = 0; i < ascii.size(); ++i) {
    if (ascii.substr(i, 3) == "deg") {
      out += "\u00b0";
      i += 2;
    } else if (ascii[i] == 'C' && (i == 0 || ascii[i - 1] == '/' || ascii[i - 1] == '(')) {
      out += "\u00b0C";
    } else if (ascii[i] == '^' && i + 1 < ascii.size() && ascii[i + 1] >= '2' &&
               ascii[i + 1] <= '4') {
      static const char* const kSup[] = {"\u00b2", "\u00b3", "\u2074"};
      out += kSup[ascii[i + 1] - '2'];
      ++i;
    } else {
      out += ascii[i];
    }
  }
  return html_escape(out);
}

/// "k1 (°/h/°C)": a coefficient's name and unit.
std::string coefficient_head(const std::string& name) {
  const std::string_view unit = sc::coefficient_unit(name);
  // The unit alone: "deg/h/C (gradient)" says what the term is in its name already.
  return html_escape(name) + " (" + unit_html(unit.substr(0, unit.find(" ("))) + ")";
}

std::string verdict_html(const FitExtras& e) {
  const std::string cls = !e.verdict ? "" : (e.verdict->value("pass", false) ? "pass" : "fail");
  return fmt::format("<span class=\"verdict {}\">{}</span>", cls, html_escape(verdict_text(e)));
}

std::string figure_box(const Figure& f) {
  return fmt::format(
      "<div class=\"figure\" data-figure=\"{}\" data-points=\"{}\">\n<h3>Fig. {}: {}</h3>\n"
      "<div class=\"chart\"></div>\n<div class=\"legend\"></div>\n{}</div>\n",
      html_escape(f.id), f.points(), html_escape(f.id), html_escape(f.title),
      f.note.empty() ? "" : "<p class=\"note\">" + html_escape(f.note) + "</p>\n");
}

std::string coefficient_table(const FitRecord& rec, const FitExtras& e) {
  std::string t =
      "<table class=\"coefficients\">\n<tr><th>term (unit)</th><th>value (term's unit)</th>"
      "<th>uncertainty, 1&sigma; (term's unit)</th><th>OLS uncertainty, 1&sigma; (term's unit)"
      "</th></tr>\n";
  const auto& f = rec.fit;
  for (std::size_t i = 0; i < f.names.size(); ++i) {
    const bool ols = e.std_errors_ols && i < e.std_errors_ols->size();
    t += kv(coefficient_head(f.names[i]),
            {num(f.coefficients[i], "{:.6e}"),
             num(i < f.std_errors.size() ? f.std_errors[i] : NAN, "{:.3e}"),
             ols ? num((*e.std_errors_ols)[i], "{:.3e}") : "-"});
  }
  return t + "</table>\n";
}

std::string evaluation_table(const FitRecord& rec) {
  std::string t = "<table class=\"evaluation\">\n";
  t += kv("std before (\u00b0/h)", {num(rec.eval.std_before_dph)});
  t += kv("std after (\u00b0/h)", {num(rec.eval.std_after_dph)});
  t += kv("std ratio (after / before)", {html_escape(std_ratio_text(rec.eval))});
  t += kv("bins (count)", {std::to_string(rec.fit.n_points)});
  t += kv("R\u00b2 (fraction)", {num(rec.fit.r2)});
  t += kv("uncertainty model", {html_escape(error_model_text(rec.fit.error_model))});
  t += kv("rate random walk", {html_escape(walk_text(rec.fit))});
  t += kv("fit", {fmt::format("{} ({}, runs {})", rec.id, html_escape(rec.created_utc),
                              fmt::join(rec.runs, ","))});
  for (const auto& w : rec.fit.warnings) t += kv("warning", {html_escape(w)});
  return t + "</table>\n";
}

/// Above this \u03c7\u00b2/dof the curve's scatter is not what its points' own variance allows:
/// 3 is beyond the 99.9 % point of \u03c7\u00b2/dof for 10 or more degrees of freedom (2.96 at 10;
/// NIST/SEMATECH e-Handbook of Statistical Methods, 1.3.6.7.4).
constexpr double kChi2FarAboveOne = 3.0;

/// What a \u03c7\u00b2/dof far above 1 means for the terms in its column (compensation/allan.hpp
/// fit_noise_terms: the standard errors are scaled by sqrt(\u03c7\u00b2/dof) when above 1).
std::string chi2_note(const std::optional<double>& chi2, const char* column) {
  if (!chi2 || !(*chi2 > kChi2FarAboveOne)) return "";
  return fmt::format(
      "<p class=\"note chi2\" data-column=\"{0}\">{0}: \u03c7\u00b2/dof {1:.3g} is far above 1: "
      "the "
      "four IEEE 952 terms do not describe this Allan curve (its points lie {2:.3g} times "
      "further from the fitted curve than their own uncertainty allows: a noise or drift that "
      "is not one of the four shapes it). The terms are the best fit of a model that does not "
      "hold; their "
      "&plusmn; uncertainties are already widened by \u221a(\u03c7\u00b2/dof) = {2:.3g}, which "
      "does not make the values right.</p>\n",
      column, *chi2, std::sqrt(*chi2));
}

std::string noise_table(const AllanCurves& a) {
  std::string t =
      "<div class=\"noise-terms\">\n<table class=\"noise\">\n<tr><th>noise term (IEEE 952 Table "
      "C.2), fitted over the whole "
      "Allan variance (unit)</th><th>before (term's unit)</th><th>after (term's unit)</th></tr>\n";
  const auto& b = a.noise_before;
  const auto& c = a.noise_after;
  // value ± standard error of the weighted fit over the whole curve (compensation/allan.hpp).
  const auto pm = [](const std::optional<double>& v, const std::optional<double>& se) {
    return v ? num(v) + (se ? " &plusmn; " + num(se, "{:.2g}") : std::string()) : "not in fit";
  };
  t += kv("quantization Q (arcsec)", {pm(b.quantization_arcsec, b.quantization_se),
                                      pm(c.quantization_arcsec, c.quantization_se)});
  t += kv("angle random walk N (\u00b0/\u221ah)",
          {pm(b.angle_random_walk_deg_rth, b.angle_random_walk_se),
           pm(c.angle_random_walk_deg_rth, c.angle_random_walk_se)});
  t += kv("bias instability B (\u00b0/h)", {pm(b.bias_instability_dph, b.bias_instability_se),
                                            pm(c.bias_instability_dph, c.bias_instability_se)});
  t += kv("flattest at \u03c4 (s)", {num(b.bias_instability_tau_s), num(c.bias_instability_tau_s)});
  t += kv("rate random walk K (\u00b0/h/\u221ah)",
          {pm(b.rate_random_walk_dph_rth, b.rate_random_walk_se),
           pm(c.rate_random_walk_dph_rth, c.rate_random_walk_se)});
  t += kv("fit \u03c7\u00b2/dof (ratio)",
          {num(b.fit_chi2_per_dof, "{:.2f}"), num(c.fit_chi2_per_dof, "{:.2f}")});
  return t + "</table>\n" + chi2_note(b.fit_chi2_per_dof, "before") +
         chi2_note(c.fit_chi2_per_dof, "after") + "</div>\n";
}

/// Coefficient names of every serial's fit, in order of first appearance: the index's columns.
std::vector<std::string> coefficient_columns(const RunReport& r) {
  std::vector<std::string> out;
  for (const auto& s : r.serials)
    if (s.fit)
      for (const auto& n : s.fit->fit.names)
        if (std::find(out.begin(), out.end(), n) == out.end()) out.push_back(n);
  return out;
}

std::string serial_summary_row(const RunReport& r, std::size_t i, const std::string& page,
                               const std::vector<std::string>& columns) {
  const auto& s = r.serials[i];
  const std::string name = page.empty() ? html_escape(s.slot.serial)
                                        : fmt::format("<a href=\"{}\">{}</a>", html_escape(page),
                                                      html_escape(s.slot.serial));
  std::string t = "<tr><td>" + name + "</td><td>" + std::to_string(s.slot.slot) + "</td><td>" +
                  (s.fit ? verdict_html(s.extras) : "no fit stored for this run") + "</td>";
  for (const auto& c : columns) {
    std::string cell = "-";
    if (s.fit) {
      const auto& f = s.fit->fit;
      const auto k =
          static_cast<std::size_t>(std::find(f.names.begin(), f.names.end(), c) - f.names.begin());
      if (k < f.names.size())
        cell = num(f.coefficients[k], "{:.4e}") + " &plusmn; " +
               num(k < f.std_errors.size() ? f.std_errors[k] : NAN, "{:.2e}");
    }
    t += "<td>" + cell + "</td>";
  }
  const auto* e = s.fit ? &s.fit->eval : nullptr;
  t += "<td>" + (e ? num(e->std_before_dph) : "-") + "</td><td>" +
       (e ? num(e->std_after_dph) : "-") + "</td><td>" +
       (e ? html_escape(std_ratio_text(*e)) : "-") + "</td><td>" +
       (s.fit ? std::to_string(s.fit->fit.n_points) : "-") + "</td><td>" + release_cell(s) +
       "</td></tr>\n";
  return t;
}

std::string verification_rows(const VerificationResult& v) {
  std::string t;
  t += kv("calibration applied", {fmt::format("fit {} (fitted on other runs; the navigation "
                                              "computer's gyro_tc_correct, clamped to its span)",
                                              v.fit_id)});
  t += kv("bins (count)",
          {fmt::format("{} ({} outside the fit's span, clamped)", v.bins, v.clamped_bins)});
  t += kv("std before (\u00b0/h)", {num(v.eval.std_before_dph)});
  t += kv("std after (\u00b0/h)", {num(v.eval.std_after_dph)});
  t += kv("std ratio (after / before)",
          {v.eval.std_ratio ? num(*v.eval.std_ratio, "{:.3f}") : "undefined"});
  t += kv("mean residual (\u00b0/h)", {num(v.mean_residual_dph)});
  if (v.drift_dph_per_c)
    t += kv(
        "residual drift against T (\u00b0/h/\u00b0C)",
        {num(*v.drift_dph_per_c, "{:.3e}") + " &plusmn; " + num(v.drift_se_dph_per_c, "{:.1e}")});
  t += kv("ADEV floor, compensated 1 Hz (\u00b0/h)", {num(v.adev_floor_dph)});
  for (const auto& w : v.warnings) t += kv("note", {html_escape(w)});
  const std::string cls = !v.verdict ? "" : (v.verdict->pass ? "pass" : "fail");
  t += kv("verdict", {fmt::format("<span class=\"verdict {}\">{}</span>", cls,
                                  html_escape(station::verdict_text(v.verdict)))});
  return t;
}

/// The serial page's verification section: each verification's figures and its Fig. 6.
std::string verification_html(const SerialReport& s, json& figures) {
  if (s.verifications.empty()) return "";
  std::string t = "<section class=\"verification\">\n<h2>Verification on this run</h2>\n";
  for (std::size_t i = 0; i < s.verifications.size(); ++i) {
    t += "<table class=\"verification-figures\">\n" + verification_rows(s.verifications[i]) +
         "</table>\n";
    if (i < s.verification_figures.size()) {
      t += "<div class=\"figures\">\n" + figure_box(s.verification_figures[i]) + "</div>\n";
      figures.push_back(figure_json(s.verification_figures[i]));
    }
  }
  return t + "</section>\n";
}

/// The index's verification table: every verification stored on this run.
std::string verification_index(const RunReport& r) {
  std::string t;
  for (const auto& s : r.serials)
    for (const auto& v : s.verifications)
      t += row({html_escape(v.serial), std::to_string(v.fit_id), num(v.eval.std_before_dph),
                num(v.eval.std_after_dph),
                v.eval.std_ratio ? num(*v.eval.std_ratio, "{:.3f}") : "undefined",
                num(v.mean_residual_dph), html_escape(station::verdict_text(v.verdict))});
  if (t.empty()) return "";
  return "<section class=\"verification\">\n<h2>Verification on this run</h2>\n<table>\n"
         "<tr><th>serial</th><th>fit applied</th><th>std before (\u00b0/h)</th>"
         "<th>std after (\u00b0/h)</th><th>std ratio (after / before)</th>"
         "<th>mean residual (\u00b0/h)</th><th>verdict</th>"
         "</tr>\n" +
         t + "</table>\n</section>\n";
}

}  // namespace

std::string figure_html(const Figure& f) {
  return figure_box(f);
}

std::string verdict_text(const FitExtras& e) {
  if (!e.verdict) return "no verdict (no part limits applied)";
  if (e.verdict->value("pass", false)) return "PASS";
  std::string out = "FAIL";
  const auto failed = e.verdict->value("failed", json::array());
  for (const auto& f : failed) {
    out += fmt::format("{} {}: {} (bound {})", out == "FAIL" ? ":" : ";",
                       f.value("limit", std::string("?")),
                       f.contains("value") ? f["value"].dump() : "?",
                       f.contains("bound") ? f["bound"].dump() : "?");
  }
  return out;
}

std::string run_record_html(const RunReport& r) {
  const auto& run = r.run;
  std::string t = "<section class=\"run-record\">\n<h2>Run record</h2>\n<table>\n";
  t += kv("run", {std::to_string(run.id)});
  t += kv("station", {html_escape(run.station)});
  t += kv("software version", {html_escape(run.software_version)});
  t += kv("configuration SHA-256", {"<code>" + html_escape(r.config_sha256) + "</code>"});
  t += kv("operator", {html_escape(run.operator_name.empty() ? "-" : run.operator_name)});
  t += kv("protocol", {html_escape(run.protocol_name)});
  t += kv("state", {html_escape(std::string(to_string(run.state)))});
  t += kv("started (UTC)", {html_escape(run.started_utc)});
  t += kv("ended (UTC)", {html_escape(run.ended_utc.empty() ? "-" : run.ended_utc)});
  if (run.sim_seed) t += kv("simulation seed", {std::to_string(*run.sim_seed)});
  return t + "</table>\n</section>\n";
}

std::string events_html(const RunReport& r) {
  std::string t = fmt::format(
      "<section class=\"events\">\n<h2>Events ({})</h2>\n<table>\n<tr><th>t (s)</th>"
      "<th>severity</th><th>source</th><th>kind</th><th>message</th></tr>\n",
      r.events.size());
  for (const auto& e : r.events)
    t += row({num(e.t_s, "{:.0f}"), html_escape(e.severity), html_escape(e.source),
              html_escape(e.kind), html_escape(e.message)});
  return t + "</table>\n</section>\n";
}

std::string index_html(const RunReport& r, const Assets& a, const std::vector<std::string>& pages) {
  const std::string title =
      fmt::format("Run {} ({}): calibration report", r.run.id, r.run.protocol_name);
  const auto columns = coefficient_columns(r);
  std::string body = "<h1>" + html_escape(title) +
                     "</h1>\n<section class=\"serials\">\n"
                     "<h2>Serials</h2>\n<table>\n<tr><th>serial</th><th>slot</th><th>verdict</th>";
  for (const auto& c : columns) body += "<th>" + coefficient_head(c) + " &plusmn; 1&sigma;</th>";
  body +=
      "<th>std before (\u00b0/h)</th><th>std after (\u00b0/h)</th><th>std ratio (after / "
      "before)</th><th>bins (count)</th><th>release</th></tr>\n";
  for (std::size_t i = 0; i < r.serials.size(); ++i)
    body += serial_summary_row(r, i, i < pages.size() ? pages[i] : "", columns);
  body += "</table>\n</section>\n" + acceptance_index_html(r) + verification_index(r) +
          run_record_html(r) + events_html(r);
  return page_html(title, body, json::array(), a);
}

std::string serial_html(const RunReport& r, const SerialReport& s, const Assets& a) {
  const std::string title =
      fmt::format("Serial {}, run {}: calibration report", s.slot.serial, r.run.id);
  std::string body = "<h1>" + html_escape(title) + "</h1>\n<p>Verdict: " + verdict_html(s.extras) +
                     "</p>\n" + release_html(s) + other_fits_html(s);
  json figures = json::array();
  if (s.fit) {
    body += fmt::format(
                "<h2>Coefficients</h2>\n<p class=\"model\">Fit {} ({}, runs {}), model {} "
                "(Zhou et al. 2013, eq. (4), with this fit's terms), &Delta;T = T &minus; {} "
                "&deg;C.</p>\n",
                s.fit->id, html_escape(s.fit->created_utc), fmt::join(s.fit->runs, ","),
                html_escape(model_formula(s.fit->fit)), num(s.fit->fit.spec.ref_temp_c)) +
            coefficient_table(*s.fit, s.extras) + evaluation_table(*s.fit) +
            "<h2>Noise terms of the 1 Hz record</h2>\n" + noise_table(s.allan) +
            "<h2>Figures</h2>\n<div class=\"figures\">\n";
    for (const auto& f : s.figures) {
      body += figure_box(f);
      figures.push_back(figure_json(f));
    }
    body += "</div>\n";
  }
  body += verification_html(s, figures);
  body += run_record_html(r) + events_html(r);
  return page_html(title, body, figures, a);
}

}  // namespace station::report
