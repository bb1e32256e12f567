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
.figure[data-points="0"] .chart { display: none; }  /* not drawn: its note says why */
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
      box.dygraph = g;  // for a test to read what was drawn
      setTimeout(function () {
        var more = tries < 3 ? T.room(g, box) : null;
        if (!more) { box.setAttribute("data-drawn", "true"); return; }
        g.destroy();
        draw(box, rows, T.widen(opts, more), tries + 1);
      }, 0);
    };
    new Dygraph(box.querySelector(".chart"), rows, opts);
  }
  // Per axis (x, y, y2) the [lo, hi] of the figure's values, intervals included; on a log
  // axis only positive ones.
  function extents(f, logX, logY) {
    var o = f.options, ex = {x: [Infinity, -Infinity], y: [Infinity, -Infinity],
                             y2: [Infinity, -Infinity]};
    function add(a, v, log) {
      if (v === null || !isFinite(v) || (log && v <= 0)) return;
      ex[a][0] = Math.min(ex[a][0], v);
      ex[a][1] = Math.max(ex[a][1], v);
    }
    f.rows.forEach(function (r) {
      add("x", r[0], logX);
      for (var k = 1; k < r.length; k++) {
        var s = (o.series || {})[o.labels[k]] || {}, a = s.axis === "y2" ? "y2" : "y";
        (Array.isArray(r[k]) ? r[k] : [r[k]]).forEach(function (v) { add(a, v, logY); });
      }
    });
    return ex;
  }
  // The ranges padded around the data (StationTicks.padded) unless the figure sets its own.
  function pad(f, opts) {
    var logX = !!(opts.axes.x && opts.axes.x.logscale), logY = !!opts.logscale;
    var ex = extents(f, logX, logY);
    if (!opts.dateWindow && ex.x[0] <= ex.x[1]) opts.dateWindow = T.padded(ex.x[0], ex.x[1], logX);
    ["y", "y2"].forEach(function (a) {
      if (!opts.axes[a].valueRange && ex[a][0] <= ex[a][1])
        opts.axes[a].valueRange = T.padded(ex[a][0], ex[a][1], logY);
    });
  }
  // A point's own error bar (a series marked "whiskers"): dygraphs' custom bars fill a band
  // between neighbouring points, which reads as a curve's interval, not a point's.
  function whiskers(e) {
    var ctx = e.drawingContext, a = e.plotArea, cap = 3;
    ctx.save();
    ctx.strokeStyle = e.color;
    ctx.fillStyle = e.color;
    ctx.lineWidth = 1;
    e.points.forEach(function (p) {
      if (typeof p.yval !== "number" || !isFinite(p.yval)) return;
      var lo = a.y + a.h * p.y_bottom, hi = a.y + a.h * p.y_top, x = p.canvasx;
      ctx.beginPath();
      if (isFinite(lo) && isFinite(hi)) {
        ctx.moveTo(x, lo); ctx.lineTo(x, hi);
        ctx.moveTo(x - cap, lo); ctx.lineTo(x + cap, lo);
        ctx.moveTo(x - cap, hi); ctx.lineTo(x + cap, hi);
        ctx.stroke();
      }
      ctx.beginPath();
      ctx.arc(x, p.canvasy, 2.5, 0, 2 * Math.PI);
      ctx.fill();
    });
    ctx.restore();
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
    Object.keys(opts.series || {}).forEach(function (name) {
      var s = opts.series[name];
      if (s.whiskers) s.plotter = whiskers;
      delete s.whiskers;  // not a dygraphs option
    });
    pad(f, opts);
    draw(box, f.rows, opts, 0);
  });
})();
)js";

}  // namespace station::report
