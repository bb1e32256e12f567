// The station's live page (schemas/api.md): the event stream, and one GET /api/live for the
// state so far once the stream is open. Nothing polls: the page re-reads /api/live only when a
// run starts or ends, when the stream reopens after an error, or when the server says 'resync'.
// Charts are decimated to MAX_POINTS and redrawn at most every DRAW_MS, so a 13 h run stays
// light. Plain browser JavaScript, no build step.
(function () {
  "use strict";

  var MAX_POINTS = 2000;  // per chart
  var DRAW_MS = 250;      // at most 4 redraws a second
  var MAX_EVENTS = 50;
  var TOKEN_KEY = "station.token";

  var S = {
    status: null,      // the last /api/live status, updated from ticks
    slotsT: null,      // run time of the slot values shown (the tick they came with), s
    trend: [],         // [[t_h, air_c, setpoint_c], ...]
    bins: {},          // serial -> [BIN, ...] sorted by t_mid_s
    events: [],        // newest first
    seq: 0,            // last stream id applied
    runId: null,
    dirty: {temp: false, bins: false},
    charts: {},        // id -> Dygraph
    rows: {},          // id -> the rows it draws
    loading: false,    // a /api/live read is under way: stream messages wait in `held`
    reloadAgain: false,
    held: [],
    busy: false        // a POST is under way
  };

  function $(id) { return document.getElementById(id); }
  function num(v, digits) {
    return (v === null || v === undefined || !isFinite(v)) ? "—" : Number(v).toFixed(digits);
  }
  function hm(t_s) {
    if (t_s === null || t_s === undefined || !isFinite(t_s)) return "—";
    var m = Math.floor(Math.max(0, t_s) / 60);
    var h = Math.floor(m / 60);
    m = m % 60;
    return h + ":" + (m < 10 ? "0" : "") + m;
  }
  function text(id, v) {
    var el = $(id);
    if (el.textContent !== v) el.textContent = v;
  }

  // ---- messages --------------------------------------------------------------------------

  function say(msg, kind) {
    var el = $("message");
    el.textContent = msg;
    el.className = "message " + (kind || "info");
  }

  // ---- status, steps, banner ---------------------------------------------------------------

  function isActive(state) { return state === "running" || state === "hold"; }

  function renderStatus() {
    var st = S.status || {};
    var run = st.run || null;
    var state = st.state || "—";
    var stEl = $("state");
    text("state", state);
    stEl.className = "state " + state;
    text("run-id", run ? String(run.id) : "—");
    text("t-s", run ? hm(run.t_s) : "—");
    $("t-s").setAttribute("data-t-s", run && run.t_s != null ? String(run.t_s) : "");
    text("speed", st.speed != null ? "×" + st.speed : "—");
    text("sim", st.sim === true ? "yes" : st.sim === false ? "no" : "—");
    text("station", st.station || "—");
    renderFleet(st.fleet);
    text("protocol", run ? run.protocol || "" : "");
    text("operator", run && run.operator ? run.operator : "—");
    var step = run && run.steps ? run.steps[run.step_index] : null;
    text("step-label", step ? stepName(step) : run ? (run.step_label || "—") : "—");
    $("recording").hidden = !(run && run.recording);
    renderSteps(run);
    renderChamber(st);
    renderSlots(st.slots || []);
    text("slots-at", hm(S.slotsT));
    renderBanner(st);
    renderButtons(st);
  }

  // "h:mm" of a duration, "—" when unknown.
  function duration(s) { return s === null || s === undefined ? "—" : hm(s); }
  function signed(v) { return num(v, 1).replace("-", "\u2212"); }

  // What a step does, with its target and nominal duration: "→ −40.0 °C at 60 °C/h, 1:05".
  function stepDetail(s) {
    if (s.kind === "set_temperature") {
      var to = s.to_start ? "start temperature" + (s.target_c != null ? " " + signed(s.target_c) +
        " °C" : "") : signed(s.target_c) + " °C";
      return "→ " + to + (s.ramp_c_per_h > 0 ? " at " + s.ramp_c_per_h + " °C/h, " +
        duration(s.duration_s) : ", as fast as the chamber goes");
    }
    if (s.kind === "soak") return "stable within ±" + s.tolerance_c + " °C for " +
      duration(s.duration_s);
    if (s.kind === "hold") return "for " + duration(s.duration_s);
    if (s.kind === "lock_turntable") return "at " + s.position_deg + "°";
    return "";
  }

  // A step without a label of its own is named for what it does (the parser labels it with its
  // kind: "set_temperature" beside the kind would say nothing).
  var KIND_NAMES = {set_temperature: "set temperature", soak: "soak", hold: "hold",
                    record_start: "open the record window", record_stop: "close the record window",
                    lock_turntable: "lock the turntable"};
  function stepName(s) {
    return s.label && s.label !== s.kind ? s.label : KIND_NAMES[s.kind] || s.kind || "step";
  }

  var stepsKey = null;
  function renderSteps(run) {
    var ol = $("steps");
    var steps = run && run.steps ? run.steps : [];
    var key = (run ? run.id : "") + "|" + JSON.stringify(steps);
    if (key !== stepsKey) {
      stepsKey = key;
      while (ol.firstChild) ol.removeChild(ol.firstChild);
      steps.forEach(function (s) {
        var li = document.createElement("li");
        li.appendChild(document.createTextNode(stepName(s)));
        var detail = stepDetail(s);
        if (detail) {
          var d = document.createElement("span");
          d.className = "detail";
          d.textContent = " " + detail;
          li.appendChild(d);
        }
        li.setAttribute("data-kind", s.kind || "");
        ol.appendChild(li);
      });
    }
    var cur = run && run.step_index != null ? run.step_index : -1;
    for (var i = 0; i < ol.children.length; i++) {
      var c = i === cur ? "current" : i < cur ? "done" : "";
      if (ol.children[i].className !== c) ol.children[i].className = c;
    }
  }

  function renderChamber(st) {
    var ch = st.chamber || {};
    text("air-c", num(ch.air_c, 2) + " °C");
    text("setpoint-c", num(ch.setpoint_c, 2) + " °C");
    // The protocol's target beside the setpoint a ramp moves towards it.
    text("target-c", st.run && st.run.target_c != null ? num(st.run.target_c, 1) + " °C" : "—");
    text("chamber-mode", (ch.mode || "—") + (ch.alarm ? " (ALARM)" : ""));
    var tb = st.table;
    text("table", tb ? num(tb.angle_deg, 1) + "°, " + num(tb.rate_dps, 2) + " °/s, " +
         (tb.mode || "—") + (tb.locked ? ", locked" : "") : "—");
    var sf = st.safety;
    if (!sf) { text("safety", "—"); return; }
    var parts = [];
    if (sf.door_closed === false) parts.push("door OPEN");
    if (sf.estop_pressed === true) parts.push("E-STOP");
    if (sf.table_interlock_open === true) parts.push("table interlock open");
    if (sf.safe_hold) parts.push("SAFE HOLD");
    text("safety", parts.length ? parts.join(", ") : "ok");
  }

  function renderSlots(slots) {
    var tb = $("slots");
    if (tb.children.length !== slots.length) {
      while (tb.firstChild) tb.removeChild(tb.firstChild);
      slots.forEach(function () {
        var tr = document.createElement("tr");
        for (var i = 0; i < 4; i++) tr.appendChild(document.createElement("td"));
        tb.appendChild(tr);
      });
    }
    slots.forEach(function (s, i) {
      var td = tb.children[i].children;
      td[0].textContent = s.serial;
      td[1].textContent = num(s.bias_dph, 4);
      td[2].textContent = num(s.temp_c, 2);
      td[3].textContent = num(s.grad_c, 3);
    });
  }

  function renderBanner(st) {
    var b = $("banner");
    var hold = st.state === "hold" || (st.safety && st.safety.safe_hold === true);
    if (hold) {
      b.textContent = "SAFE HOLD — chamber held at its air temperature, turntable stopped." +
        " See the events below.";
      b.className = "banner hold";
      b.hidden = false;
    } else if (st.state === "fault") {
      b.textContent = "FAULT — the last run failed or the devices do not answer." +
        " See the events below.";
      b.className = "banner fault";
      b.hidden = false;
    } else {
      b.hidden = true;
      b.textContent = "";
      b.className = "banner";
    }
  }

  function renderButtons(st) {
    var active = isActive(st.state) && st.run;
    $("btn-start").disabled = S.busy || !S.status || !!active;
    $("btn-stop").disabled = S.busy || !active;
    $("btn-abort").disabled = S.busy || !active;
  }

  // The bias charts' captions name the width the daemon bins at (status.bin_s), never a
  // width written into the page.
  function renderBinWidth() {
    var w = S.status && typeof S.status.bin_s === "number" ? S.status.bin_s + " s " : "";
    document.querySelectorAll(".bin-s").forEach(function (el) {
      if (el.textContent !== w) el.textContent = w;
    });
  }

  // ---- data: /api/live and the stream ------------------------------------------------------

  function applyLive(live) {
    S.status = live.status || {};
    S.runId = S.status.run ? S.status.run.id : null;
    S.slotsT = S.status.run ? S.status.run.t_s : null;
    S.trend = (live.trend || []).map(function (p) { return [p[0] / 3600, p[1], p[2]]; });
    thin(S.trend);
    S.bins = {};
    var b = live.bins || {};
    Object.keys(b).forEach(function (serial) {
      S.bins[serial] = (b[serial] || []).slice().sort(function (x, y) {
        return x.t_mid_s - y.t_mid_s;
      });
    });
    S.events = (live.events || []).slice().sort(function (x, y) { return y.id - x.id; })
      .slice(0, MAX_EVENTS);
    S.seq = live.seq || 0;
    renderStatus();
    renderEvents();
    renderBinWidth();
    document.dispatchEvent(new CustomEvent("station:status", {detail: S.status}));  // results.js
    S.dirty.temp = S.dirty.bins = true;
    scheduleDraw();
  }

  // One read of /api/live; stream messages that arrive meanwhile are held and applied after it
  // (those the snapshot already includes, id <= seq, are dropped).
  function reload() {
    if (S.loading) { S.reloadAgain = true; return; }
    S.loading = true;
    fetch("/api/live", {cache: "no-store"}).then(function (r) {
      if (!r.ok) throw new Error("HTTP " + r.status);
      return r.json();
    }).then(function (live) {
      applyLive(live);
    }).catch(function (e) {
      say("cannot read /api/live: " + e.message, "error");
    }).then(function () {
      S.loading = false;
      var held = S.held;
      S.held = [];
      held.forEach(function (m) { dispatch(m.type, m.id, m.data); });
      if (S.reloadAgain) { S.reloadAgain = false; reload(); }
    });
  }

  // The forwarder to the fleet's PostgreSQL ([fleet]; absent: the box stays hidden): its state
  // and what it has still to send; the last failure as the tooltip.
  function renderFleet(f) {
    $("fleet-box").hidden = !f;
    if (!f) return;
    var pending = f.pending_rows > 0 ? ", " + f.pending_rows + " rows pending" : ", up to date";
    var held = f.held_items > 0 ? ", " + f.held_items + " held" : "";
    // Waiting on server: the call it waits for (its seconds are in /api/status, not streamed).
    var detail = f.state === "backing off" ? " " + f.backoff_s + " s"
               : f.state === "waiting on server" && f.waiting_for ? " (" + f.waiting_for + ")"
               : "";
    text("fleet", f.state + detail + pending + held);
    $("fleet").className = "fleet " + f.state.replace(/ /g, "-");
    $("fleet").title = f.last_error || "";
  }

  function dispatch(type, id, data) {
    if (S.loading) { S.held.push({type: type, id: id, data: data}); return; }
    if (id !== null && id <= S.seq) return;
    if (id !== null) S.seq = id;
    if (type === "tick") onTick(data);
    else if (type === "bin") onBin(data);
    else if (type === "event") onEvent(data);
    else if (type === "run") onRun(data);
    else if (type === "fleet") { (S.status || (S.status = {})).fleet = data; renderFleet(data); }
    else if (type === "resync") reload();
  }

  function onTick(d) {
    var st = S.status || (S.status = {});
    // Entering or leaving a hold (or a fault): the snapshot has the safety inputs and devices.
    var edge = st.state !== undefined && (st.state !== d.state ||
      (st.safety && st.safety.safe_hold !== undefined && st.safety.safe_hold !== d.safe_hold));
    st.state = d.state;
    if (!st.safety) st.safety = {};
    st.safety.safe_hold = d.safe_hold;
    // Each tick carries all the page shows of the rig, so every value is of the clock's time.
    if ("chamber" in d) st.chamber = d.chamber;
    if ("table" in d) st.table = d.table;
    if (d.safety) st.safety = d.safety;
    if (st.run) {
      st.run.t_s = d.t_s;
      st.run.target_c = d.target_c;
      st.run.step_index = d.step_index;
      st.run.step_label = d.step_label;
      st.run.recording = d.recording;
    }
    if (d.slots) {
      var bySerial = {};
      (st.slots || []).forEach(function (s) { bySerial[s.serial] = s; });
      st.slots = d.slots.map(function (s) {
        var o = bySerial[s.serial] || {serial: s.serial};
        o.bias_dph = s.bias_dph;
        if ("temp_c" in s) o.temp_c = s.temp_c;
        if ("grad_c" in s) o.grad_c = s.grad_c;
        return o;
      });
      S.slotsT = d.t_s;
    }
    var t_h = d.t_s / 3600;
    var last = S.trend.length ? S.trend[S.trend.length - 1][0] : -Infinity;
    if (t_h > last) {
      S.trend.push([t_h, d.air_c, d.setpoint_c]);
      thin(S.trend);
      S.dirty.temp = true;
      scheduleDraw();
    }
    scheduleStatus();
    if (edge) reload();
  }

  function onBin(d) {
    if (S.runId !== null && d.run_id !== S.runId) return;
    var list = S.bins[d.serial] || (S.bins[d.serial] = []);
    var b = d.bin;
    list = list.filter(function (x) { return Math.abs(x.t_mid_s - b.t_mid_s) > 1e-6; });
    list.push(b);
    list.sort(function (x, y) { return x.t_mid_s - y.t_mid_s; });
    S.bins[d.serial] = list;
    S.dirty.bins = true;
    scheduleDraw();
  }

  function onEvent(e) {
    if (S.events.some(function (x) { return x.id === e.id; })) return;
    S.events.unshift(e);
    if (S.events.length > MAX_EVENTS) S.events.length = MAX_EVENTS;
    renderEvents();
  }

  function onRun(d) {
    var ended = d.state !== "running";
    var el = $("run-end");
    el.textContent = "run " + d.run_id + (ended ? " ended: " + d.state : " started");
    el.setAttribute("data-run-state", d.state);
    if (S.status && S.runId === d.run_id) {
      // Shown at once; the snapshot read next says what the station does now.
      S.status.state = ended ? (/^fail/.test(d.state) ? "fault" : "idle") : "running";
      renderStatus();
    }
    reload();
  }

  function renderEvents() {
    var ul = $("events");
    while (ul.firstChild) ul.removeChild(ul.firstChild);
    S.events.forEach(function (e) {
      var li = document.createElement("li");
      li.className = e.severity || "info";
      var w = document.createElement("span");
      w.className = "when";
      w.textContent = "run " + e.run_id + " " + hm(e.t_s);
      li.appendChild(w);
      li.appendChild(document.createTextNode(
        (e.severity || "info") + " " + (e.source || "") + "/" + (e.kind || "") + ": " +
        (e.message || "")));
      ul.appendChild(li);
    });
  }

  // Status text is cheap but a fast simulation sends 10 ticks a second: coalesce to frames.
  var statusPending = false;
  function scheduleStatus() {
    if (statusPending) return;
    statusPending = true;
    setTimeout(function () { statusPending = false; renderStatus(); }, 100);
  }

  // ---- charts ------------------------------------------------------------------------------

  // Over MAX_POINTS: drop every other point, keeping the newest (the trend's resolution halves
  // each time, so a 13 h run ends with ~1000-2000 evenly thinned points).
  function thin(a) {
    if (a.length <= MAX_POINTS) return;
    var lastP = a[a.length - 1];
    var out = [];
    for (var i = 0; i < a.length; i += 2) out.push(a[i]);
    if (out[out.length - 1] !== lastP) out.push(lastP);
    a.length = 0;
    Array.prototype.push.apply(a, out);
  }

  var drawTimer = null, lastDraw = 0;
  function scheduleDraw() {
    if (drawTimer !== null) return;
    var wait = Math.max(0, DRAW_MS - (Date.now() - lastDraw));
    drawTimer = setTimeout(function () {
      drawTimer = null;
      lastDraw = Date.now();
      draw();
    }, wait);
  }

  function hmAxis(v) { return hm(v * 3600); }
  function timeAxis() {
    return {valueFormatter: hmAxis, ticker: window.StationTicks.hours()};
  }

  function plot(id, rows, opts, points) {
    var el = $(id);
    var note = $(id.replace("chart-", "note-"));
    if (!rows.length) {
      if (S.charts[id]) { S.charts[id].destroy(); delete S.charts[id]; }
      note.hidden = false;
      el.hidden = true;
      el.setAttribute("data-points", "0");
      return;
    }
    note.hidden = true;
    el.hidden = false;
    var g = S.charts[id];
    if (g && g.getLabels().join("\u0001") !== opts.labels.join("\u0001")) {
      g.destroy();
      delete S.charts[id];
      g = null;
    }
    S.rows[id] = rows;
    if (!g) {
      var T = window.StationTicks;
      opts.axes = opts.axes || {};
      ["x", "y"].forEach(function (a) { opts.axes[a] = opts.axes[a] || {}; });
      opts.axes.x.ticker = opts.axes.x.ticker || T.numeric(true);
      opts.axes.y.ticker = T.numeric(false);
      create(id, el, opts);
    } else {
      g.updateOptions({file: rows});
    }
    el.setAttribute("data-points", String(points));
  }

  // A chart whose labels need more room than they have is drawn anew with it (widths only
  // grow, so this settles; updateOptions would leave the old plot beside the new plot area).
  function create(id, el, opts) {
    var T = window.StationTicks;
    opts.drawCallback = function (g) {
      setTimeout(function () {
        if (S.charts[id] !== g) return;
        var more = T.room(g, el);
        if (!more) return;
        g.destroy();
        create(id, el, T.widen(opts, more));
      }, 0);
    };
    S.charts[id] = new Dygraph(el, S.rows[id], opts);
  }

  function draw() {
    if (typeof Dygraph === "undefined") { say("dygraphs did not load", "error"); return; }
    if (S.dirty.temp) {
      S.dirty.temp = false;
      plot("chart-temp", S.trend.slice(), {
        labels: ["t (h:mm)", "air °C", "setpoint °C"],
        labelsDiv: $("legend-temp"), legend: "always", labelsSeparateLines: false,
        xlabel: "t (h:mm)", ylabel: "temperature (°C)", connectSeparatedPoints: false,
        colors: ["#1f5fbf", "#d9480f"], strokeWidth: 1.5,
        axes: {x: timeAxis()}
      }, S.trend.length);
    }
    if (S.dirty.bins) {
      S.dirty.bins = false;
      var serials = Object.keys(S.bins).sort();
      var time = binRows(serials, function (b) { return b.t_mid_s / 3600; });
      var temp = binRows(serials, function (b) { return b.temp_c; });
      var labelsT = ["t (h:mm)"].concat(serials), labelsC = ["T (°C)"].concat(serials);
      plot("chart-bias-time", time.rows, {
        labels: labelsT, labelsDiv: $("legend-bias-time"), legend: "always",
        xlabel: "t (h:mm)", ylabel: "bias (°/h)", drawPoints: true, pointSize: 2.5,
        strokeWidth: 1, connectSeparatedPoints: true, xRangePad: 8, axes: {x: timeAxis()}
      }, time.points);
      plot("chart-bias-temp", temp.rows, {
        labels: labelsC, labelsDiv: $("legend-bias-temp"), legend: "always",
        xlabel: "T (°C)", ylabel: "bias (°/h)", drawPoints: true, pointSize: 2.5,
        strokeWidth: 0, connectSeparatedPoints: false, xRangePad: 8
      }, temp.points);
    }
  }

  // Rows [x, s1, s2, ...] with null where a serial has no bin at that x, sorted by x; at most
  // MAX_POINTS rows (a 13 h run has ~80 bins per serial, so this only guards odd cases).
  function binRows(serials, xOf) {
    var rows = [], points = 0;
    serials.forEach(function (s, j) {
      S.bins[s].forEach(function (b) {
        var x = xOf(b);
        if (x === null || x === undefined || !isFinite(x)) return;
        var row = [x];
        for (var k = 0; k < serials.length; k++) row.push(null);
        row[j + 1] = b.bias_dph;
        rows.push(row);
      });
    });
    rows.sort(function (a, b) { return a[0] - b[0]; });
    // Rows at the same x merge (bins of every serial share their windows' times).
    var merged = [];
    rows.forEach(function (r) {
      var m = merged.length ? merged[merged.length - 1] : null;
      if (m && m[0] === r[0]) {
        for (var k = 1; k < r.length; k++) if (r[k] !== null) m[k] = r[k];
      } else {
        merged.push(r);
      }
    });
    while (merged.length > MAX_POINTS) {
      var out = [];
      for (var i = 0; i < merged.length; i += 2) out.push(merged[i]);
      merged = out;
    }
    merged.forEach(function (r) {
      for (var k = 1; k < r.length; k++) if (r[k] !== null && r[k] !== undefined) points++;
    });
    return {rows: merged, points: points};
  }

  // ---- the event stream ---------------------------------------------------------------------

  // The stream starts at the server's last message when it opens (no replay), so the snapshot
  // is read after each open: messages it already holds (id <= seq) are dropped, none is missed.
  var es = null, retryMs = 5000, triedSnapshot = false;
  function openStream() {
    es = new EventSource("/api/events/stream");
    ["tick", "bin", "event", "run", "fleet", "resync"].forEach(function (type) {
      es.addEventListener(type, function (m) {
        var id = m.lastEventId ? parseInt(m.lastEventId, 10) : null;
        var data;
        if (type === "resync") { dispatch(type, null, {}); return; }
        try { data = m.data ? JSON.parse(m.data) : {}; } catch (e) {
          say("unreadable " + type + " message: " + e.message, "error");
          return;
        }
        dispatch(type, isFinite(id) ? id : null, data);
      });
    });
    es.onopen = function () {
      text("conn", "live");
      retryMs = 5000;
      triedSnapshot = true;
      reload();
    };
    es.onerror = function () {
      // No stream yet: show the snapshot anyway (once; the next open reads it again).
      if (!triedSnapshot) { triedSnapshot = true; reload(); }
      if (es.readyState === EventSource.CLOSED) {
        // The server refused the stream (e.g. 503, too many streams): EventSource gives up, so
        // open a new one later, backing off.
        text("conn", "closed; retry in " + Math.round(retryMs / 1000) + " s");
        es.close();
        setTimeout(openStream, retryMs);
        retryMs = Math.min(retryMs * 2, 60000);
      } else {
        text("conn", "reconnecting");
      }
    };
  }

  // ---- commands -------------------------------------------------------------------------------

  function token() {
    var t = sessionStorage.getItem(TOKEN_KEY);
    if (t) return t;
    t = window.prompt("Bearer token (the one line of the station's token file, DB.token):", "");
    if (t === null) return null;
    t = t.trim();
    if (!t) return null;
    sessionStorage.setItem(TOKEN_KEY, t);
    return t;
  }

  function post(url, body, what) {
    var t = token();
    if (!t) { say(what + ": no token given", "error"); return; }
    S.busy = true;
    renderButtons(S.status || {});
    say(what + "…", "info");
    fetch(url, {
      method: "POST",
      headers: {"Authorization": "Bearer " + t, "Content-Type": "application/json"},
      body: JSON.stringify(body || {})
    }).then(function (r) {
      return r.text().then(function (txt) {
        var j = null;
        try { j = txt ? JSON.parse(txt) : null; } catch (e) { j = null; }
        var err = j && j.error ? j.error : txt.trim();
        if (r.status === 401 || r.status === 403) {
          sessionStorage.removeItem(TOKEN_KEY);
          say(what + ": token refused (HTTP " + r.status + ")" + (err ? ": " + err : "") +
              ". The next command asks for the token again.", "error");
        } else if (!r.ok) {
          say(what + ": HTTP " + r.status + (err ? ": " + err : ""), "error");
        } else {
          say(what + ": accepted (HTTP " + r.status + ")", "info");
        }
      });
    }).catch(function (e) {
      say(what + ": " + e.message, "error");
    }).then(function () {
      S.busy = false;
      renderButtons(S.status || {});
    });
  }

  function runId() {
    return S.status && S.status.run ? S.status.run.id : null;
  }

  // The start form (start_form.js): a field per slot for the run's gyros.
  function start() {
    window.StartForm.open(S.status || {}, function (body) {
      post("/api/runs", body, "start " + body.protocol);
    });
  }

  function stop() {
    var id = runId();
    if (id === null) return;
    post("/api/runs/" + encodeURIComponent(id) + "/stop", {}, "stop run " + id);
  }

  function abort() {
    var id = runId();
    if (id === null) return;
    if (!window.confirm("Abort run " + id + "? It ends now without a fit.")) return;
    post("/api/runs/" + encodeURIComponent(id) + "/abort", {}, "abort run " + id);
  }

  function init() {
    $("btn-start").addEventListener("click", start);
    $("btn-stop").addEventListener("click", stop);
    $("btn-abort").addEventListener("click", abort);
    // The stream first, then the snapshot when it opens (see openStream).
    openStream();
  }

  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", init);
  else init();
})();
