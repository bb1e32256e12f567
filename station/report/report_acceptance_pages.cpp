// The report's acceptance pages (issue 36): a page per test kind, per serial its figures' table
// and its figures (report_acceptance.cpp).
#include <fmt/format.h>

#include "station/report/report_html.hpp"
#include "station/report/report_page.hpp"
#include "station/report/report_pages.hpp"

namespace station::report {

using nlohmann::json;
namespace {

constexpr double kMradPerRad = 1e3;

/// "v ± se" in one format ("-" for a value that is not finite).
std::string pm(double v, double se, const char* spec = "{:.5g}") {
  return num(v, spec) + " &plusmn; " + num(se, "{:.2g}");
}

/// The figures' boxes, each also added to the page's figure data.
std::string figures_html(const std::vector<Figure>& figs, json& data) {
  std::string t = "<div class=\"figures\">\n";
  for (const auto& f : figs) {
    t += figure_html(f);
    data.push_back(figure_json(f));
  }
  return t + "</div>\n";
}

std::string ladder_table(const SerialAcceptance& a) {
  std::string t =
      "<table class=\"acceptance-figures\">\n<tr><th>ladder</th><th>gyro temperature "
      "(&deg;C)</th><th>scale factor K &plusmn; 1&sigma; (pulse/arcsec)</th><th>bias "
      "&plusmn; 1&sigma; (&deg;/h)</th><th>nonlinearity, largest (ppm of full scale)</th>"
      "<th>nonlinearity, RMS (ppm of full scale)</th><th>asymmetry &plusmn; 1&sigma; (ppm)</th>"
      "<th>points used (count)</th><th>left out (count)</th></tr>\n";
  for (const auto& l : a.ladders) {
    t += "<tr><td>" + html_escape(l.label) + "</td><td>" + num(l.temp_c, "{:.2f}") + "</td>";
    if (!l.fit) {
      t += "<td colspan=\"7\" class=\"note\">Not computed: " + html_escape(l.fit.error()) +
           "</td></tr>\n";
      continue;
    }
    const auto& f = *l.fit;
    const auto& asym = f.asymmetry;
    t += "<td>" + pm(f.sf_pulse_per_arcsec, f.sf_se_pulse_per_arcsec, "{:.8f}") + "</td><td>" +
         pm(f.bias_dph, f.bias_se_dph, "{:.3g}") + "</td><td>" +
         num(f.nonlinearity_max_ppm_fs, "{:.3g}") + "</td><td>" +
         num(f.nonlinearity_rms_ppm_fs, "{:.3g}") + "</td><td>" +
         (asym ? pm(asym->asymmetry_ppm, asym->asymmetry_se_ppm, "{:.3g}")
               : html_escape(f.asymmetry_note)) +
         "</td><td>" + std::to_string(f.points_used) + "</td><td>" +
         std::to_string(f.points_excluded + static_cast<std::size_t>(l.missing)) + "</td></tr>\n";
  }
  t += "</table>\n";
  if (!a.sf_vs_temp || !*a.sf_vs_temp) return t;
  const auto& tc = a.sf_vs_temp->value();
  return t + "<table class=\"acceptance-figures\">\n" +
         kv("temperature coefficient &plusmn; 1&sigma; (ppm/&deg;C)",
            {pm(tc.tc_ppm_per_c, tc.tc_se_ppm_per_c, "{:.3g}")}) +
         kv(fmt::format("K at {:g} &deg;C &plusmn; 1&sigma; (pulse/arcsec)", tc.ref_temp_c),
            {pm(tc.sf_ref_pulse_per_arcsec, tc.sf_ref_se_pulse_per_arcsec, "{:.8f}")}) +
         kv("plateaus (count)", {std::to_string(tc.plateaus)}) + "</table>\n";
}

std::string turn_on_table(const TurnOnStep& step) {
  if (!step.result) return "";
  const auto& r = step.result.value();
  const auto& rep = r.repeatability;
  std::string t =
      "<table class=\"acceptance-figures\">\n<tr><th>turn-on</th><th>bias &plusmn; 1&sigma; "
      "(&deg;/h)</th><th>final value (&deg;/h)</th><th>warm-up (s)</th></tr>\n";
  for (std::size_t k = 0; k < r.turn_ons.size(); ++k) {
    const auto& o = r.turn_ons[k];
    t += kv(fmt::format("turn-on {}", k + 1),
            {pm(o.bias_dph, o.bias_se_dph, "{:.4g}"), num(o.final_dph, "{:.4g}"),
             o.warmup_s ? num(*o.warmup_s, "{:.0f}") : "not settled"});
  }
  t += "</table>\n<table class=\"acceptance-figures\">\n";
  t += kv("repeatability &sigma; (&deg;/h)", {num(rep.repeatability_dph, "{:.3g}")});
  t += kv(fmt::format("its {:g} % interval (&deg;/h)", rep.confidence * 100),
          {num(rep.repeatability_lower_dph, "{:.3g}") + " to " +
           num(rep.repeatability_upper_dph, "{:.3g}")});
  t += kv("mean turn-on bias (&deg;/h)", {num(rep.mean_bias_dph, "{:.4g}")});
  t += kv("RMS of the turn-on biases' own 1&sigma; (&deg;/h)", {num(r.mean_bias_se_dph, "{:.3g}")});
  t +=
      kv("warm-up band, &plusmn; around the final value (&deg;/h)", {num(step.band_dph, "{:.3g}")});
  t += kv("longest warm-up (s)", {r.max_warmup_s ? num(*r.max_warmup_s, "{:.0f}") : "-"});
  t += kv("turn-ons not settled (count)", {std::to_string(r.not_settled)});
  return t + "</table>\n";
}

/// A horizontal input axis's positions (acceptance_run.hpp: heading_error_rad's conventions).
std::string horizontal_positions_table(const SerialAcceptance& a) {
  std::string t =
      "<table class=\"acceptance-figures\">\n<tr><th>positions</th><th>gyro temperature "
      "(&deg;C)</th><th>nominal heading at table angle 0 (&deg;)</th><th>heading error "
      "&plusmn; 1&sigma; (mrad, clockwise)</th><th>bias if level &plusmn; 1&sigma; "
      "(&deg;/h)</th><th>Earth rate amplitude / &Omega; cos &phi; &plusmn; 1&sigma;</th>"
      "<th>positions used (count)</th><th>left out (count)</th></tr>\n";
  for (const auto& p : a.positions) {
    if (!p.nominal_heading_deg) continue;
    t += "<tr><td>" + html_escape(p.label) + "</td><td>" + num(p.temp_c, "{:.2f}") + "</td><td>" +
         num(*p.nominal_heading_deg, "{:g}") + "</td>";
    if (!p.horizontal) {
      t += "<td colspan=\"5\" class=\"note\">Not computed: " + html_escape(p.horizontal.error()) +
           "</td></tr>\n";
      continue;
    }
    const auto& h = *p.horizontal;
    t += "<td>" +
         pm(heading_error_rad(h) * kMradPerRad, h.in_plane_misalignment_se_rad * kMradPerRad,
            "{:.3g}") +
         "</td><td>" + pm(h.bias_if_level_dph, h.bias_if_level_se_dph, "{:.3g}") + "</td><td>" +
         pm(h.amplitude_ratio, h.amplitude_ratio_se, "{:.5f}") + "</td><td>" +
         std::to_string(h.fit.positions) + "</td><td>" + std::to_string(p.excluded) +
         "</td></tr>\n";
  }
  return t +
         "</table>\n<p class=\"note\">The axis's elevation out of the table's plane adds "
         "&Omega; sin &phi; sin e to the constant with the bias: on a table turning about up it "
         "is not measured, and the bias is the bias if the axis is level.</p>\n";
}

std::string positions_table(const SerialAcceptance& a) {
  if (a.positions.empty()) return "";
  if (a.positions.front().nominal_heading_deg) return horizontal_positions_table(a);
  std::string t =
      "<table class=\"acceptance-figures\">\n<tr><th>positions</th><th>gyro temperature "
      "(&deg;C)</th><th>input axis tilt &plusmn; 1&sigma; (mrad)</th><th>tilt direction on the "
      "table &plusmn; 1&sigma; (&deg;)</th><th>bias &plusmn; 1&sigma; (&deg;/h)</th><th>Earth "
      "rate amplitude A &plusmn; 1&sigma; (&deg;/h)</th><th>positions used (count)</th>"
      "<th>left out (count)</th></tr>\n";
  for (const auto& p : a.positions) {
    t += "<tr><td>" + html_escape(p.label) + "</td><td>" + num(p.temp_c, "{:.2f}") + "</td>";
    if (!p.fit) {
      t += "<td colspan=\"6\" class=\"note\">Not computed: " + html_escape(p.fit.error()) +
           "</td></tr>\n";
      continue;
    }
    const auto& v = *p.fit;
    t += "<td>" + pm(v.tilt_rad * kMradPerRad, v.tilt_se_rad * kMradPerRad, "{:.3g}") +
         "</td><td>" + pm(v.tilt_direction_table_deg, v.tilt_direction_se_deg, "{:.1f}") +
         "</td><td>" + pm(v.bias_dph, v.bias_se_dph, "{:.3g}") + "</td><td>" +
         pm(v.fit.amplitude_dph, v.fit.amplitude_se_dph, "{:.3g}") + "</td><td>" +
         std::to_string(v.fit.positions) + "</td><td>" + std::to_string(p.excluded) +
         "</td></tr>\n";
  }
  return t + "</table>\n";
}

/// Each power_cycles step of a serial: its name, table and figures (T1.n and T2.n with one step,
/// T1.n.j and T2.n.j, j the step's place, with several).
std::string turn_on_steps_html(const SerialAcceptanceReport& s, const std::string& n, json& data) {
  const auto steps = turn_on_steps_of(s);
  std::string t;
  for (std::size_t j = 0; j < steps.size(); ++j) {
    const auto& step = steps[j];
    const std::string id = steps.size() == 1 ? n : n + "." + std::to_string(j + 1);
    if (const auto title = turn_on_step_title(step); !title.empty())
      t += "<h3 class=\"turn-on-step\">" + html_escape(title) + "</h3>\n";
    t += turn_on_table(step) + figures_html({turn_on_figure("T1." + id, s.figures.serial, step),
                                             warmup_figure("T2." + id, s.figures.serial, step)},
                                            data);
  }
  return t;
}

/// One serial's section of page `p`: its table, then its figures (ids numbered by serial).
std::string serial_section(const SerialAcceptanceReport& s, std::size_t k, AcceptancePage p,
                           json& data) {
  const auto& a = s.figures;
  std::string t = "<section class=\"acceptance-serial\">\n<h2>" + html_escape(a.serial) + "</h2>\n";
  const std::string n = std::to_string(k + 1);
  switch (p) {
    case AcceptancePage::scale_factor:
      return t + ladder_table(a) +
             figures_html(
                 {ladder_residuals_figure("S1." + n, a), sf_temperature_figure("S2." + n, a)},
                 data) +
             "</section>\n";
    case AcceptancePage::turn_on:
      return t + turn_on_steps_html(s, n, data) + "</section>\n";
    case AcceptancePage::positions:
      return t + positions_table(a) + figures_html({positions_figure("P1." + n, s)}, data) +
             "</section>\n";
  }
  return t + "</section>\n";
}

/// What the page's figures follow: the definitions and their sources, in the maths' headers.
std::string method_note(AcceptancePage p) {
  switch (p) {
    case AcceptancePage::scale_factor:
      return "<p class=\"method\">Each ladder's least-squares straight line (equal weights, the "
             "error bars each point's standard error), output against "
             "input rate (the table's read-back rate plus the Earth rate along the input axis); "
             "nonlinearity is the residual in ppm of full-scale output, asymmetry the positive "
             "against the negative scale factor with one bias; the temperature coefficient from "
             "the plateaus' scale factors (IEEE Std 647-2006 test items; definitions in "
             "compensation/scale_factor.hpp).</p>\n";
    case AcceptancePage::turn_on:
      return "<p class=\"method\">Each turn-on's bias over the second half of its powered time; "
             "the repeatability is the sample standard deviation of those biases with its "
             "chi-square interval; the warm-up time is where the bias last leaves the band around "
             "its final value (compensation/turn_on.hpp).</p>\n";
    case AcceptancePage::positions:
      return "<p class=\"method\">The output at rest at each table angle, fitted with c + "
             "A&middot;cos(&theta; &minus; &theta;0); for an input axis up its tilt from A "
             "against the horizontal Earth rate and the bias from c, for a horizontal one its "
             "heading error from &theta;0 (the table angle &theta; counterclockwise seen from "
             "above, headings clockwise from north) (compensation/positions.hpp).</p>\n";
  }
  return "";
}

}  // namespace

std::vector<AcceptancePage> acceptance_pages(const std::vector<SerialAcceptanceReport>& a) {
  bool ladder = false, turn_on = false, positions = false;
  for (const auto& s : a) {
    ladder = ladder || !s.figures.ladders.empty();
    turn_on = turn_on || s.figures.turn_on.has_value();
    positions = positions || !s.figures.positions.empty() || !s.figures.positions_note.empty();
  }
  std::vector<AcceptancePage> out;
  if (ladder) out.push_back(AcceptancePage::scale_factor);
  if (turn_on) out.push_back(AcceptancePage::turn_on);
  if (positions) out.push_back(AcceptancePage::positions);
  return out;
}

std::string acceptance_page_title(AcceptancePage p) {
  switch (p) {
    case AcceptancePage::scale_factor:
      return "Scale factor";
    case AcceptancePage::turn_on:
      return "Turn-on";
    case AcceptancePage::positions:
      return "Positions";
  }
  return "";
}

std::string acceptance_page_slug(AcceptancePage p) {
  switch (p) {
    case AcceptancePage::scale_factor:
      return "scale-factor";
    case AcceptancePage::turn_on:
      return "turn-on";
    case AcceptancePage::positions:
      return "positions";
  }
  return "";
}

std::string acceptance_page_name(std::int64_t run_id, AcceptancePage p) {
  return fmt::format("run-{}-{}.html", run_id, acceptance_page_slug(p));
}

std::string acceptance_index_html(const RunReport& r) {
  const auto pages = acceptance_pages(r.acceptance);
  if (pages.empty()) return "";
  std::string t = "<section class=\"acceptance\">\n<h2>Acceptance tests</h2>\n<ul>\n";
  for (const auto p : pages)
    t += fmt::format("<li><a href=\"{}\">{}</a></li>\n", acceptance_page_name(r.run.id, p),
                     acceptance_page_title(p));
  return t + "</ul>\n</section>\n";
}

std::string acceptance_html(const RunReport& r, AcceptancePage p, const Assets& a) {
  const std::string title =
      fmt::format("Run {} ({}): {}", r.run.id, r.run.protocol_name, acceptance_page_title(p));
  std::string body = "<h1>" + html_escape(title) + "</h1>\n<p><a href=\"" +
                     index_page_name(r.run.id) + "\">The run's report</a></p>\n" + method_note(p);
  json figures = json::array();
  for (std::size_t k = 0; k < r.acceptance.size(); ++k)
    body += serial_section(r.acceptance[k], k, p, figures);
  body += run_record_html(r);
  return page_html(title, body, figures, a);
}

}  // namespace station::report
