// The report page's style sheet and its script: dygraphs with the station's round ticks and
// label room (station/web/ticks.js).
#include "station/report/report_pages.hpp"

namespace station::report {

const std::string_view kReportCss = R"css(
body { font-family: sans-serif; margin: 1.5em; color: #222; max-width: 1400px; }
h1 { font-size: 1.5em; } h2 { font-size: 1.15em; margin-top: 1.4em; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.6em; text-align: left; }
th[scope="row"] { font-weight: normal; background: #f4f4f4; }
td.num { text-align: right; font-family: monospace; }
.pass { color: #17702a; font-weight: bold; } .fail { color: #b01818; font-weight: bold; }
.figures { display: grid; grid-template-columns: 1fr 1fr; gap: 1em 2em; }
.figure { break-inside: avoid; }
.figure h3 { font-size: 1em; margin: 0.3em 0; }
.figure .chart { width: 100%; height: 280px; }
.figure .legend { font-size: 0.8em; min-height: 1.2em; }
.figure .legend .dygraph-legend { position: static; width: auto; background: none; }
.note { font-style: italic; color: #8a5a00; }
.dygraph-axis-label { white-space: nowrap; }
)css";

// Each figure to Dygraph with the station's tickers (station/web/ticks.js, inlined before this
// script); a figure whose labels need more room is drawn anew with it before it is marked drawn.
const std::string_view kRenderJs = R"js(
(function () {
  "use strict";
  var T = window.StationTicks;
  // Drawn; once the drawing returns, drawn anew with wider label room if a label needs it.
  function draw(box, rows, opts, tries) {
    var settled = false;
    opts.drawCallback = function (g) {
      if (settled) return;
      settled = true;
      setTimeout(function () {
        var more = tries < 3 ? T.room(g, box) : null;
        if (!more) { box.setAttribute("data-drawn", "true"); return; }
        g.destroy();
        draw(box, rows, T.widen(opts, more), tries + 1);
      }, 0);
    };
    new Dygraph(box.querySelector(".chart"), rows, opts);
  }
  var figures = JSON.parse(document.getElementById("report-figures").textContent);
  figures.forEach(function (f) {
    var box = document.querySelector('[data-figure="' + f.id + '"]');
    if (!box || f.rows.length === 0) return;
    var opts = f.options;
    opts.labelsDiv = box.querySelector(".legend");
    opts.axes = opts.axes || {};
    ["x", "y", "y2"].forEach(function (a) {
      opts.axes[a] = opts.axes[a] || {};
      opts.axes[a].ticker = T.numeric(a === "x");
    });
    opts.axes.y2.independentTicks = true;  // its own round values, not y's positions
    draw(box, f.rows, opts, 0);
  });
})();
)js";

}  // namespace station::report
