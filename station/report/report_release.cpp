// The serial page's notes on releases and on fits made after the run: dated, each with its own
// model, beside the run's own fit (which they never replace).
#include <fmt/format.h>

#include "station/report/report_model.hpp"
#include "station/report/report_pages.hpp"

namespace station::report {

namespace {

/// "fit 6 released DATE by NAME (note)", with the fit's model when `fit` is given.
std::string release_line(const ReleaseRow& r, const std::optional<FitRecord>& fit = {}) {
  std::string t = fmt::format("fit {} released {} by {}", r.fit_id, html_escape(r.released_utc),
                              html_escape(r.released_by));
  if (!r.note.empty()) t += " (" + html_escape(r.note) + ")";
  if (fit && fit->id == r.fit_id) t += ", model " + html_escape(model_formula(fit->fit));
  if (r.override_reason)
    t += " <span class=\"fail\">over its verdict: " + html_escape(*r.override_reason) + "</span>";
  return t;
}

}  // namespace

std::string release_html(const SerialReport& s) {
  std::string t = "<p class=\"release\">";
  const bool current = s.fit && s.current_release && s.current_release->fit_id == s.fit->id;
  const auto& other = s.current_release_fit;
  if (current)
    t += "<span class=\"pass\">RELEASED</span>: " + release_line(*s.current_release) +
         ". This fit is the gyro's calibration (`station export`).";
  else if (s.fit_release)
    t += "Superseded: " + release_line(*s.fit_release) + "; the released calibration is now " +
         (s.current_release ? release_line(*s.current_release, other) : std::string("none")) + ".";
  else if (s.current_release)
    t += "This run's fit is not released; the gyro's calibration is " +
         release_line(*s.current_release, other) + ".";
  else
    t += "Not released: no fit of this gyro is released (`station release --fit ID --by NAME`).";
  return t + "</p>\n";
}

std::string release_cell(const SerialReport& s) {
  if (s.fit && s.current_release && s.current_release->fit_id == s.fit->id)
    return fmt::format("<span class=\"pass\">released</span> (fit {})", s.fit->id);
  if (s.current_release) return fmt::format("fit {} is released", s.current_release->fit_id);
  return "not released";
}

std::string other_fits_html(const SerialReport& s) {
  if (s.other_fits.empty()) return "";
  std::string t =
      "<section class=\"later-fits\">\n<h2>Later fits of this run's bins</h2>\n<p>Made after the "
      "run; the coefficients and figures below are the run's own fit" +
      (s.fit ? fmt::format(" (fit {})", s.fit->id) : std::string()) + ".</p>\n<ul>\n";
  for (const auto& o : s.other_fits) {
    t += fmt::format("<li data-fit=\"{}\">{}: fit {} over runs {}, model {}", o.fit.id,
                     html_escape(o.fit.created_utc), o.fit.id, fmt::join(o.fit.runs, ","),
                     html_escape(model_formula(o.fit.fit)));
    t += o.release ? "; " + release_line(*o.release) : std::string("; not released");
    t += "</li>\n";
  }
  return t + "</ul>\n</section>\n";
}

}  // namespace station::report
