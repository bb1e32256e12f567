// The live page's results panel: after a run, each serial's fit as GET /api/runs/{id} gives it
// (k1 ± SE, k0 ± SE, B0, std ratio after/before, verdict, model) and the link to the run's report
// (GET /reports/NAME, served from the database). It reads the run when live.js says the status
// changed (the 'station:status' event after each /api/live read: page load, a run's start or
// end, a resync): nothing polls. Hidden while a run runs. Plain browser JavaScript.
(function () {
  "use strict";

  var shown = null;  // "runId/state" of the run drawn, so one status read draws it once

  function $(id) { return document.getElementById(id); }
  function sci(v, digits) {
    return typeof v === "number" && isFinite(v) ? v.toExponential(digits) : "—";
  }
  // A coefficient with its standard error: "1.234e-3 ± 5.6e-5"; "—" where the model has none.
  function withError(fit, name) {
    if (!fit.coefficients || typeof fit.coefficients[name] !== "number") return "—";
    var se = fit.std_errors ? fit.std_errors[name] : null;
    return sci(fit.coefficients[name], 3) + (typeof se === "number" ? " ± " + sci(se, 1) : "");
  }
  function cell(tr, text, cls) {
    var td = document.createElement("td");
    td.textContent = text;
    if (cls) td.className = cls;
    tr.appendChild(td);
    return td;
  }

  function row(slot) {
    var tr = document.createElement("tr");
    tr.setAttribute("data-serial", slot.serial);
    cell(tr, String(slot.slot + 1));  // the API's slot is the stored index; people count from 1
    cell(tr, slot.serial);
    var f = slot.fit;
    if (!f) {
      cell(tr, "no fit for this run", "muted").colSpan = 6;
      return tr;
    }
    cell(tr, withError(f, "k1"), "num k1");
    cell(tr, withError(f, "k0"), "num k0");
    cell(tr, sci(f.coefficients.B0, 3), "num b0");
    cell(tr, typeof f.std_ratio === "number" ? f.std_ratio.toFixed(3) : "undefined", "num ratio");
    var v = cell(tr, f.verdict_text || "—", "verdict");
    v.className += f.verdict ? (f.verdict.pass ? " pass" : " fail") : " none";
    cell(tr, f.terms || "—", "model");
    return tr;
  }

  function render(run) {
    var body = $("results-rows");
    while (body.firstChild) body.removeChild(body.firstChild);
    (run.slots || []).forEach(function (s) { body.appendChild(row(s)); });
    $("results-run").textContent = run.id + " (" + run.state + ")";
    var link = $("results-report");
    link.hidden = !run.report;
    if (run.report) link.href = run.report;
    $("results").setAttribute("data-run", String(run.id));
    $("results").hidden = false;
  }

  function load(id, key) {
    fetch("/api/runs/" + id, {cache: "no-store"}).then(function (r) {
      if (!r.ok) throw new Error("HTTP " + r.status);
      return r.json();
    }).then(function (run) {
      if (run.state === "running") return;  // its results come with its end
      shown = key;
      render(run);
    }).catch(function (e) {
      $("results-note").textContent = "cannot read run " + id + ": " + e.message;
    });
  }

  // The run to show: this process's last run, else the newest in the database.
  function onStatus(st) {
    if (st.state === "running" || st.state === "hold") {
      $("results").hidden = true;
      shown = null;
      return;
    }
    if (typeof st.last_run_id === "number") {
      var key = st.last_run_id + "/" + st.state;
      if (key !== shown) load(st.last_run_id, key);
      return;
    }
    fetch("/api/runs?limit=1", {cache: "no-store"}).then(function (r) {
      return r.ok ? r.json() : [];
    }).then(function (runs) {
      if (runs.length && (runs[0].id + "/" + st.state) !== shown)
        load(runs[0].id, runs[0].id + "/" + st.state);
    });
  }

  document.addEventListener("station:status", function (e) { onStatus(e.detail || {}); });
})();
