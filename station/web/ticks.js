// Axis ticks for dygraphs, shared by the live page (served as /static/ticks.js) and the report
// (inlined into each page by station/report): round values, one number format per axis, labels
// that fit. Plain browser JavaScript; defines window.StationTicks.
//  - numeric(horizontal): a dygraphs `ticker`. A linear axis gets the multiples of a 1-2-5 step
//    inside the range, labelled with the decimals the step needs (a shared exponent when the
//    numbers are very small or large); a log axis 1-2-5 (else 1, else every n-th decade) times
//    powers of ten. Only ticks inside the drawn range, so no label is cut at an edge; on a
//    horizontal axis the step grows until neighbouring labels do not touch.
//  - hours(): the same for a time axis in hours, labelled h:mm at 1, 2, 5, 10, 15, 20, 30 min,
//    1, 2, 3, 6, 12, 24 h steps.
//  - room(g, el): after a drawing, the label width each axis needs beyond what it has (its widest
//    label plus, for y and y2, the rotated axis title's strip, which dygraphs does not reserve),
//    or null; widen(opts, more) the options with those widths. A chart that needs more room is
//    drawn anew with them (dygraphs' updateOptions keeps the old plot outside the new plot area).
//  - padded(lo, hi, log): a data range with room around it, for dateWindow / valueRange.
(function () {
  "use strict";
  var FONT_PX = 14;  // dygraphs' axisLabelFontSize
  function decimals(step) { return Math.max(0, -Math.floor(Math.log10(step) + 1e-9)); }
  function fixed(v, d) {
    var s = v.toFixed(d);
    return /^-0(\.0*)?$/.test(s) ? s.slice(1) : s;
  }
  function textPx(s) { return s.length * FONT_PX * 0.62 + 6; }
  function linearLabels(vs, step) {
    var big = Math.max.apply(null, vs.map(Math.abs));
    if (step >= 1e-4 && big < 1e6) {
      var d = decimals(step);
      return vs.map(function (v) { return fixed(v, d); });
    }
    var e = Math.floor(Math.log10(big || step));
    var d2 = decimals(step / Math.pow(10, e));
    return vs.map(function (v) { return fixed(v / Math.pow(10, e), d2) + "e" + e; });
  }
  // The first step of `steps` whose ticks in [lo, hi] leave room for their labels.
  function stepTicks(lo, hi, pixels, horizontal, steps, label) {
    var span = hi - lo, last = null;
    for (var i = 0; i < steps.length; i++) {
      var step = steps[i], vs = [];
      for (var k = Math.ceil(lo / step - 1e-9); k * step <= hi + step * 1e-9; k++) vs.push(k * step);
      var labels = label(vs, step);
      var room = horizontal ? Math.max.apply(null, labels.map(textPx)) + 8 : FONT_PX * 2;
      last = vs.map(function (v, j) { return {v: v, label: labels[j]}; });
      if (vs.length <= 1 || pixels * step / span >= room) return last;
    }
    return last;
  }
  function linearTicks(lo, hi, pixels, horizontal) {
    if (!(hi > lo)) return [{v: lo, label: linearLabels([lo], Math.abs(lo) || 1)[0]}];
    var p = Math.pow(10, Math.floor(Math.log10((hi - lo) / 20))), steps = [];
    [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000].forEach(function (m) { steps.push(m * p); });
    return stepTicks(lo, hi, pixels, horizontal, steps, linearLabels);
  }
  function logLabel(v) {
    var e = Math.floor(Math.log10(v) + 1e-9);
    var m = Math.round(v / Math.pow(10, e));
    return e >= -4 && e <= 5 ? fixed(v, Math.max(0, -e)) : m + "e" + e;
  }
  function logTicks(lo, hi, pixels, horizontal) {
    var e0 = Math.floor(Math.log10(lo)), e1 = Math.ceil(Math.log10(hi));
    var px = function (a, b) { return pixels * Math.log(b / a) / Math.log(hi / lo); };
    var plans = [[[1, 2, 5], 1], [[1], 1], [[1], 2], [[1], 3], [[1], 5], [[1], 10]];
    for (var i = 0; i < plans.length; i++) {
      var mults = plans[i][0], skip = plans[i][1], vs = [];
      for (var e = e0; e <= e1; e++) {
        if ((e - e0) % skip) continue;
        mults.forEach(function (m) {
          var v = m * Math.pow(10, e);
          if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) vs.push(v);
        });
      }
      if (vs.length < 2) break;
      var labels = vs.map(logLabel), ok = true;
      for (var j = 1; j < vs.length; j++) {
        var need = horizontal ? (textPx(labels[j]) + textPx(labels[j - 1])) / 2 + 8 : FONT_PX * 2;
        if (px(vs[j - 1], vs[j]) < need) ok = false;
      }
      if (ok) return vs.map(function (v, k) { return {v: v, label: labels[k]}; });
    }
    return linearTicks(lo, hi, pixels, horizontal);
  }
  function numeric(horizontal) {
    return function (lo, hi, pixels, opts) {
      if (lo > hi) { var t = lo; lo = hi; hi = t; }
      return opts("logscale") && lo > 0 ? logTicks(lo, hi, pixels, horizontal)
                                        : linearTicks(lo, hi, pixels, horizontal);
    };
  }
  // "h:mm" of a time in hours (never "-0:00"; rounded to the minute).
  function hm(t_h) {
    var m = Math.round(Math.max(0, t_h) * 60);
    var h = Math.floor(m / 60);
    m = m % 60;
    return h + ":" + (m < 10 ? "0" : "") + m;
  }
  var HOUR_STEPS = [1, 2, 5, 10, 15, 20, 30, 60, 120, 180, 360, 720, 1440].map(function (m) {
    return m / 60;
  });
  function hours() {
    return function (lo, hi, pixels) {
      if (lo > hi) { var t = lo; lo = hi; hi = t; }
      if (!(hi > lo)) return [{v: lo, label: hm(lo)}];
      return stepTicks(lo, hi, pixels, true, HOUR_STEPS, function (vs) { return vs.map(hm); });
    };
  }
  function widest(el, axis) {
    var sel = axis === "y" ? ".dygraph-axis-label-y:not(.dygraph-axis-label-y2)"
                           : ".dygraph-axis-label-" + axis;
    var w = 0;
    el.querySelectorAll(sel).forEach(function (lab) {
      var r = document.createRange();
      r.selectNodeContents(lab);
      w = Math.max(w, Math.ceil(r.getBoundingClientRect().width));
    });
    return w;
  }
  // Label widths each axis needs beyond what it has ({x: {axisLabelWidth: px}, ...}), or null.
  function room(g, el) {
    var title = g.getOption("yLabelWidth") + 6, more = {}, any = false;
    [["y", title], ["y2", title], ["x", 8]].forEach(function (a) {
      var need = widest(el, a[0]) + a[1];
      if (need > g.getOptionForAxis("axisLabelWidth", a[0])) {
        more[a[0]] = {axisLabelWidth: need};
        any = true;
      }
    });
    return any ? more : null;
  }
  // `opts` with the label widths of `more` (a new object; opts.axes copied one level deep).
  function widen(opts, more) {
    var o = {}, axes = {};
    Object.keys(opts).forEach(function (k) { o[k] = opts[k]; });
    Object.keys(opts.axes || {}).forEach(function (a) {
      axes[a] = {};
      Object.keys(opts.axes[a]).forEach(function (k) { axes[a][k] = opts.axes[a][k]; });
    });
    Object.keys(more).forEach(function (a) {
      axes[a] = axes[a] || {};
      axes[a].axisLabelWidth = more[a].axisLabelWidth;
    });
    o.axes = axes;
    return o;
  }
  // [lo, hi] of the data widened by PAD of its span on each side (of its decades on a log
  // axis), so no point sits on an axis line or is cut at the plot's edge (dygraphs ends the x
  // range at the outermost points); a single value gets +-10 % of itself (+-1 at 0).
  var PAD = 0.05;
  function padded(lo, hi, log) {
    if (log && lo > 0) {
      var a = Math.log10(lo), b = Math.log10(hi), s = b - a || 1;
      return [Math.pow(10, a - PAD * s), Math.pow(10, b + PAD * s)];
    }
    if (!(hi > lo)) {
      var d = Math.abs(lo) / 10 || 1;
      return [lo - d, hi + d];
    }
    return [lo - PAD * (hi - lo), hi + PAD * (hi - lo)];
  }
  window.StationTicks = {numeric: numeric, hours: hours, room: room, widen: widen, hm: hm,
                         padded: padded};
})();
