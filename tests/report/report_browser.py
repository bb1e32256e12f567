#!/usr/bin/env python3
"""The report in a real browser: a simulated run's database, `station report`, then the index and
one serial page opened from file:// in headless Chromium (Selenium + chromedriver). Checks that
every figure element is there with its points, that dygraphs drew it (a canvas inside, the
page's data-drawn mark), that no resource was fetched and the console logged nothing SEVERE, and
keeps a screenshot as the test's artifact.

Exit 0 pass, 1 fail, 77 skip (Chromium, chromedriver or python3-selenium absent).
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

SKIP = 77
FIGURES = ["2a", "2b", "3", "4", "5a", "5b"]
RAMPS = ["ramp_00", "ramp_10", "ramp_20"]


def skip(why):
    print(f"SKIP: {why}")
    sys.exit(SKIP)


def fail(why):
    print(f"FAIL: {why}")
    sys.exit(1)


def browser():
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        skip(f"python3-selenium is not importable by {sys.executable} (Debian: python3-selenium)")
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if not chromium or not driver:
        skip("chromium and chromedriver are needed (Debian: chromium chromium-driver)")
    opts = webdriver.ChromeOptions()
    opts.binary_location = chromium
    for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1400,2400",
              "--disable-dev-shm-usage"]:
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(executable_path=driver), options=opts)


def station(bin_path, *args):
    r = subprocess.run([bin_path, *args], capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        fail(f"station {' '.join(args)}: exit {r.returncode}: {r.stderr.strip()}")
    return r.stdout


def make_db(bin_path, db, gyros, ramps, verify=False, protocol=None):
    for ext in ("", "-wal", "-shm", ".lock"):
        if os.path.exists(db + ext):
            os.remove(db + ext)
    for ramp in RAMPS if ramps else []:
        station(bin_path, "run", "--sim", "--gyros", str(gyros), "--protocol", ramp, "--new",
                "--db", db, "--json")
    out = station(bin_path, "run", "--sim", "--gyros", str(gyros), "--new", "--db", db, "--json",
                  *(["--verify"] if verify else []),
                  *(["--protocol", protocol] if protocol else []))
    return json.loads(out)


def check_verification(drv, index, page, report):
    """run --sim --verify: the verification run's index lists each verification, its serial page
    shows the verification table and Fig. 6 drawn, and says which fit is released."""
    from selenium.webdriver.common.by import By
    load(drv, index)
    rows = drv.find_elements(By.CSS_SELECTOR, "section.verification tr")
    if len(rows) != 1 + len(report["verifications"]):
        fail(f"{index}: verification table has {len(rows)} rows, expected "
             f"{1 + len(report['verifications'])}")
    cells = [c.text for c in drv.find_elements(By.CSS_SELECTOR, ".serials td")]
    if not any("is released" in c for c in cells):
        fail(f"{index}: no serial row names its released fit: {cells}")
    load(drv, page)
    rel = drv.find_element(By.CSS_SELECTOR, "p.release").text
    fit = report["verifications"][0]["fit_id"]
    if "not released" not in rel or f"fit {fit} released" not in rel:
        fail(f"{page}: release paragraph {rel!r} does not say this run's fit is not released and "
             f"fit {fit} is the calibration")
    el = drv.find_element(By.CSS_SELECTOR, '[data-figure="6"]')
    deadline = time.time() + 10
    while el.get_attribute("data-drawn") != "true" and time.time() < deadline:
        time.sleep(0.1)
    if el.get_attribute("data-drawn") != "true" or int(el.get_attribute("data-points")) <= 0:
        fail(f"{page}: Fig. 6 (verification) not drawn")
    table = drv.find_element(By.CSS_SELECTOR, "table.verification-figures").text
    for word in ("std before", "std after", "mean residual", "ADEV floor", "verdict"):
        if word not in table:
            fail(f"{page}: verification table lacks '{word}': {table!r}")
    print(f"verification: {len(rows) - 1} rows on the index, Fig. 6 drawn on {page}")
    return el


def load(drv, path):
    drv.get("file://" + os.path.abspath(path))
    deadline = time.time() + 20
    while time.time() < deadline:
        if drv.execute_script("return document.readyState") == "complete":
            return
        time.sleep(0.1)
    fail(f"{path}: did not load")


def check_clean(drv, path):
    severe = [e for e in drv.get_log("browser") if e.get("level") == "SEVERE"]
    if severe:
        fail(f"{path}: console errors: {severe}")
    fetched = drv.execute_script(
        "return performance.getEntriesByType('resource').map(function (e) { return e.name; })")
    if fetched:
        fail(f"{path}: fetched resources (must be self-contained): {fetched}")


def check_figures(drv, path, ramps):
    from selenium.webdriver.common.by import By
    for fig in FIGURES:
        els = drv.find_elements(By.CSS_SELECTOR, f'[data-figure="{fig}"]')
        if len(els) != 1:
            fail(f"{path}: {len(els)} elements with data-figure={fig}")
        el = els[0]
        points = int(el.get_attribute("data-points"))
        if fig == "3" and not ramps:
            note = el.find_elements(By.CSS_SELECTOR, ".note")
            if points != 0 or not note or not note[0].is_displayed() or "ramp" not in note[0].text:
                fail(f"{path}: fig 3 without ramp runs: points {points}, no visible note")
            continue
        if points <= 0:
            fail(f"{path}: fig {fig} has data-points {points}")
        deadline = time.time() + 10
        while el.get_attribute("data-drawn") != "true" and time.time() < deadline:
            time.sleep(0.1)
        if el.get_attribute("data-drawn") != "true":
            fail(f"{path}: fig {fig} was not drawn by dygraphs")
        if not el.find_elements(By.CSS_SELECTOR, ".chart canvas"):
            fail(f"{path}: fig {fig} has no canvas")
        print(f"fig {fig}: {points} points drawn")
    if ramps:
        series = drv.execute_script(
            "var f = JSON.parse(document.getElementById('report-figures').textContent);"
            "return f.filter(function (x) { return x.id === '3'; })[0].options.labels;")
        for r in RAMPS:
            if not any(label.startswith(r) for label in series):
                fail(f"{path}: fig 3 has no {r} series: {series}")


# Every drawn figure's tick labels and titles, as the browser laid them out: per axis the
# labels' text, their text boxes (a Range over the text: what is painted, not the label's div),
# whether the text overflows its div (dygraphs' labels clip: "1.000e+" for "1.000e+4"), and the
# boxes of the axis titles and the figure's heading.
TICKS_JS = """
var out = [];
function box(r) { return {l: r.left, t: r.top, r: r.right, b: r.bottom}; }
function textBox(el) { var r = document.createRange(); r.selectNodeContents(el);
  return box(r.getBoundingClientRect()); }
var figs = JSON.parse(document.getElementById('report-figures').textContent);
document.querySelectorAll('[data-figure][data-drawn="true"]').forEach(function (fig) {
  var f = figs.filter(function (x) { return x.id === fig.getAttribute('data-figure'); })[0];
  var axes = {x: [], y: [], y2: []};
  fig.querySelectorAll('.dygraph-axis-label').forEach(function (el) {
    if (!el.textContent.trim()) return;  // a tick with a grid line and no label
    var a = el.classList.contains('dygraph-axis-label-x') ? 'x'
          : el.classList.contains('dygraph-axis-label-y2') ? 'y2' : 'y';
    axes[a].push({text: el.textContent, box: textBox(el), scroll: el.scrollWidth,
                  client: el.clientWidth});
  });
  var titles = [];
  fig.querySelectorAll('.dygraph-xlabel, .dygraph-ylabel, .dygraph-y2label, h3')
     .forEach(function (el) { titles.push({text: el.textContent, box: textBox(el)}); });
  out.push({id: f.id, axes: axes, titles: titles,
            chart: box(fig.querySelector('.chart').getBoundingClientRect()),
            log: {x: !!(f.options.axes && f.options.axes.x && f.options.axes.x.logscale),
                  y: !!f.options.logscale, y2: !!f.options.logscale}});
});
return out;
"""
NUMBER = re.compile(r"^-?\d+(\.\d+)?(e[-+]?\d+)?$")


def overlap(a, b, slack=0.5):
    return (min(a["r"], b["r"]) - max(a["l"], b["l"]) > slack and
            min(a["b"], b["b"]) - max(a["t"], b["t"]) > slack)


def axis_problems(name, labels, log):
    """Equal texts, incomplete or clipped numbers, and steps that are not one round 1-2-5 step
    (linear) or 1-2-5 times a power of ten (log) in one format."""
    out = []
    texts = [lab["text"] for lab in labels]
    if len(set(texts)) != len(texts):
        out.append(f"{name}: repeated labels {texts}")
    for lab in labels:
        if not NUMBER.match(lab["text"]):
            out.append(f"{name}: label {lab['text']!r} is not a complete number")
        if lab["scroll"] > lab["client"] + 1:
            out.append(f"{name}: label {lab['text']!r} is cut ({lab['scroll']} px of text in "
                       f"{lab['client']} px)")
    if out or len(labels) < 2:
        return out + ([] if len(labels) >= 2 else [f"{name}: {len(labels)} labels"])
    vals = sorted(float(t) for t in texts)
    if log:
        for v in vals:
            m = v / 10 ** math.floor(math.log10(v) + 1e-9)
            if min(abs(m - k) for k in (1, 2, 3, 5)) > 1e-6:
                out.append(f"{name}: log tick {v} is not 1, 2 or 5 times a power of ten")
        return out
    steps = [b - a for a, b in zip(vals, vals[1:])]
    step = steps[0]
    if max(abs(s - step) for s in steps) > 1e-6 * step:
        out.append(f"{name}: uneven steps {texts}")
    m = step / 10 ** math.floor(math.log10(step) + 1e-9)
    if min(abs(m - k) for k in (1, 2, 5, 10)) > 1e-6:
        out.append(f"{name}: step {step} is not 1, 2 or 5 times a power of ten: {texts}")
    if len({len(t.split("e")[0].partition(".")[2]) for t in texts}) != 1:
        out.append(f"{name}: labels in different formats {texts}")
    return out


def check_ticks(drv, path, expect):
    """Every figure in `expect` drawn with readable axes: per axis, round steps in one format,
    no repeated, cut or incomplete label; no label over another, over an axis title or over the
    figure's heading, and none outside its chart."""
    figs = drv.execute_script(TICKS_JS)
    found = {f["id"] for f in figs}
    if not set(expect) <= found:
        fail(f"{path}: figures {sorted(set(expect) - found)} not drawn")
    problems = []
    for f in figs:
        labels = []
        for axis in ("x", "y", "y2"):
            if f["axes"][axis] or axis != "y2":
                problems += axis_problems(f"fig {f['id']} {axis}", f["axes"][axis],
                                          f["log"][axis])
            labels += [(axis, lab) for lab in f["axes"][axis]]
        c = f["chart"]
        for axis, lab in labels:
            b = lab["box"]
            if b["l"] < c["l"] - 1 or b["r"] > c["r"] + 1 or b["t"] < c["t"] - 1:
                problems.append(f"fig {f['id']} {axis}: {lab['text']!r} outside the chart")
            for t in f["titles"]:
                if overlap(b, t["box"]):
                    problems.append(f"fig {f['id']} {axis}: {lab['text']!r} overlaps the title "
                                    f"{t['text']!r}")
        for i, (a1, l1) in enumerate(labels):
            for a2, l2 in labels[i + 1:]:
                if overlap(l1["box"], l2["box"]):
                    problems.append(f"fig {f['id']}: {a1} {l1['text']!r} overlaps {a2} "
                                    f"{l2['text']!r}")
        print(f"fig {f['id']} ticks: " + "; ".join(
            f"{a} " + " ".join(lab["text"] for lab in f["axes"][a]) for a in ("x", "y", "y2")
            if f["axes"][a]))
    if problems:
        fail(f"{path}: tick labels:\n  " + "\n  ".join(problems))


# What dygraphs drew (the page keeps each Dygraph on its figure element): per series the points
# the figure's data gives it, the points drawn with a finite value, and the drawn points closer
# than MARGIN_PX to an edge of the plot area (on an axis line, or cut at the edge).
MARGIN_PX = 2
DRAWN_JS = """
var figs = JSON.parse(document.getElementById('report-figures').textContent), out = [];
document.querySelectorAll('[data-figure][data-drawn="true"]').forEach(function (box) {
  var id = box.getAttribute('data-figure'), g = box.dygraph;
  if (!g) { out.push({id: id, missing: true}); return; }
  var f = figs.filter(function (x) { return x.id === id; })[0], a = g.getArea(), m = arguments[0];
  var series = [];
  g.layout_.setNames.forEach(function (name, i) {
    var col = f.options.labels.indexOf(name), given = 0, drawn = 0, edge = [];
    f.rows.forEach(function (r) { if (r[col] !== null) given++; });
    g.layout_.points[i].forEach(function (p) {
      if (typeof p.yval !== 'number' || !isFinite(p.yval)) return;
      drawn++;
      if (p.canvasx < a.x + m || p.canvasx > a.x + a.w - m || p.canvasy < a.y + m ||
          p.canvasy > a.y + a.h - m) edge.push([p.xval, p.yval]);
    });
    series.push({name: name, given: given, drawn: drawn, edge: edge.slice(0, 3)});
  });
  out.push({id: id, series: series});
});
return out;
""".replace("arguments[0]", str(MARGIN_PX))


def check_drawn(drv, path, fitted_curves=True):
    """Every point the data gives is drawn (Fig. 5b's fitted IEEE 952 curves included, which
    dygraphs' error bars once left undrawn) and none on an axis or cut at the plot's edge."""
    problems = []
    figs = drv.execute_script(DRAWN_JS)
    for f in figs:
        if f.get("missing"):
            problems.append(f"fig {f['id']}: no dygraph kept on its element")
            continue
        for s in f["series"]:
            if s["drawn"] != s["given"]:
                problems.append(f"fig {f['id']} '{s['name']}': {s['drawn']} of {s['given']} "
                                "points drawn")
            if s["edge"]:
                problems.append(f"fig {f['id']} '{s['name']}': points within {MARGIN_PX} px of "
                                f"the plot's edge: {s['edge']}")
    if fitted_curves:
        fig5b = [f for f in figs if f["id"] == "5b"]
        names = [s["name"] for f in fig5b for s in f.get("series", []) if s["drawn"] > 1]
        for want in ("fitted terms (before)", "fitted terms (after)"):
            if want not in names:
                problems.append(f"fig 5b: no curve '{want}' drawn (drawn: {names})")
    if problems:
        fail(f"{path}: drawn data:\n  " + "\n  ".join(problems))
    print(f"{path}: {len(figs)} figures, every point drawn inside the plot area")


def shoot_figures(drv, artifacts, name):
    """A screenshot of each figure and of the noise-term table, for docs/ (README says which)."""
    from selenium.webdriver.common.by import By
    for el in drv.find_elements(By.CSS_SELECTOR, "[data-figure]"):
        el.screenshot(os.path.join(artifacts, f"{name}-fig-{el.get_attribute('data-figure')}.png"))
    for el in drv.find_elements(By.CSS_SELECTOR, "div.noise-terms"):
        el.screenshot(os.path.join(artifacts, f"{name}-noise.png"))


# A number in a table cell ("1.5", "-2.3e-04", "1.2e-03 ± 2e-05"): its column or row heading
# must name its unit in parentheses; ids and counts that have none are listed here.
CELL_NUMBER = re.compile(r"^-?\d+(\.\d+)?(e[-+]?\d+)?( ± .*)?$")
NO_UNIT = {"serial", "slot", "fit applied", "run", "simulation seed"}
UNITS_JS = """
var out = [];
document.querySelectorAll('table').forEach(function (t) {
  var head = Array.prototype.map.call(t.rows[0].cells, function (c) {
    return c.tagName === 'TH' ? c.textContent : ''; });
  Array.prototype.forEach.call(t.rows, function (tr, i) {
    if (i === 0 && tr.cells[0].tagName === 'TH' && tr.cells[0].scope !== 'row') return;
    var rowHead = tr.cells[0].tagName === 'TH' ? tr.cells[0].textContent : '';
    Array.prototype.forEach.call(tr.cells, function (c, j) {
      if (c.tagName === 'TD') out.push({text: c.textContent.trim(), col: head[j] || '',
                                         row: rowHead});
    });
  });
});
return out;
"""


def check_units(drv, path):
    """Every number in every table has a heading naming its unit."""
    bad = []
    for c in drv.execute_script(UNITS_JS):
        if not CELL_NUMBER.match(c["text"]):
            continue
        heads = [h for h in (c["row"], c["col"]) if h]
        if any(h in NO_UNIT or re.search(r"\(.+\)", h) for h in heads):
            continue
        bad.append(f"{c['text']!r} under {heads}")
    if bad:
        fail(f"{path}: numbers without a unit in their heading: {bad[:10]}")
    print(f"{path}: every table number has a unit in its heading")


def check_pdf(bin_path, db, run_id, out_dir, gyros):
    """--pdf: every page printed by headless Chromium to a PDF file."""
    shutil.rmtree(out_dir, ignore_errors=True)
    files = station(bin_path, "report", "--db", db, "--run", str(run_id), "--out", out_dir,
                    "--pdf").split()
    pdfs = [f for f in files if f.endswith(".pdf")]
    if len(pdfs) != 1 + gyros:
        fail(f"--pdf: expected {1 + gyros} PDFs, got {pdfs}")
    for pdf in pdfs:
        with open(pdf, "rb") as f:
            if f.read(5) != b"%PDF-":
                fail(f"{pdf}: not a PDF")
    print(f"--pdf: {len(pdfs)} PDFs")


# The acceptance pages (issue 36): page name part -> per serial its figures, each drawn when the
# run's JSON says its figure was computed, else a visible note saying why.
ACCEPTANCE_PROTOCOL = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                   "acceptance_two_plateaus.toml")
ACCEPTANCE_PAGES = {"scale-factor": ["S1", "S2"], "turn-on": ["T1", "T2"], "positions": ["P1"]}


def expected_acceptance(serial):
    """Per figure of a serial (S1.. P1): the reason it cannot be drawn, or None when it is drawn
    (the run's own JSON: acceptance_json)."""
    def why(items):
        ok = [i for i in items if i.get("ok")]
        return None if ok else "; ".join(i.get("error", "?") for i in items) or "none"
    sf = serial.get("sf_vs_temp")
    out = {"S1": why(serial["ladders"]),
           "S2": None if sf and sf.get("ok") else (sf or {}).get("error", "plateaus"),
           "P1": why(serial["positions"])}
    # Every power_cycles step has its own T1 and T2 (figure id T1.n.j with two or more steps).
    steps = serial.get("turn_on_steps") or \
        [serial.get("turn_on") or {"ok": False, "error": "no power cycles"}]
    for j, step in enumerate(steps):
        for fig in ("T1", "T2"):
            out[fig if len(steps) == 1 else f"{fig}.{j + 1}"] = \
                None if step.get("ok") else step["error"]
    return out


def acceptance_figures(slug, expect):
    """The page's figure kinds of one serial: T1 and T2 once per power_cycles step."""
    return [f for f in expect if f.split(".")[0] in ACCEPTANCE_PAGES[slug]]


FIGURE_TEXT_JS = """
var out = {}, figs = JSON.parse(document.getElementById('report-figures').textContent);
figs.forEach(function (f) { out[f.id] = {x: f.options.xlabel, y: f.options.ylabel}; });
document.querySelectorAll('[data-figure]').forEach(function (el) {
  var o = out[el.getAttribute('data-figure')] || {};
  o.drawnx = Array.prototype.map.call(el.querySelectorAll('.dygraph-xlabel'),
                                      function (e) { return e.textContent; }).join('');
  o.drawny = Array.prototype.map.call(el.querySelectorAll('.dygraph-ylabel'),
                                      function (e) { return e.textContent; }).join('');
  out[el.getAttribute('data-figure')] = o;
});
return out;
"""
UNIT = re.compile(r"\(.+\)")
NOT_A_NUMBER = re.compile(r"\b(nan|NaN|inf|Infinity|undefined)\b")


def check_acceptance_page(drv, path, slug, report, artifacts, name):
    """One acceptance page: each serial's figures drawn with unit-labelled axes and round ticks
    where the run computed them, the reason shown where it did not; no NaN anywhere."""
    from selenium.webdriver.common.by import By
    load(drv, path)
    check_clean(drv, path)
    check_units(drv, path)
    text = drv.find_element(By.TAG_NAME, "body").text
    if NOT_A_NUMBER.search(text):
        fail(f"{path}: the page shows {NOT_A_NUMBER.search(text).group(0)!r}")
    labels = drv.execute_script(FIGURE_TEXT_JS)
    drawn = []
    for k, serial in enumerate(report["acceptance"]):
        expect = expected_acceptance(serial)
        figs = acceptance_figures(slug, expect)
        if slug == "turn-on" and "turn_on_steps" in serial:
            # Each step named above its figures (label, step number, temperature).
            shown = [h.text for h in drv.find_elements(By.CSS_SELECTOR, "h3.turn-on-step")]
            for step in serial["turn_on_steps"]:
                head = f"{step['label']} (step {step['step_index'] + 1}"
                if not any(h.startswith(head) for h in shown):
                    fail(f"{path}: no heading for power_cycles step {head!r}: {shown}")
        for fig in figs:
            head, _, step = fig.partition(".")
            fid = f"{head}.{k + 1}" + (f".{step}" if step else "")
            els = drv.find_elements(By.CSS_SELECTOR, f'[data-figure="{fid}"]')
            if len(els) != 1:
                fail(f"{path}: {len(els)} elements with data-figure={fid}")
            el, points = els[0], int(els[0].get_attribute("data-points"))
            note = el.find_elements(By.CSS_SELECTOR, ".note")
            if expect[fig] is not None:
                shown = note[0].text if note and note[0].is_displayed() else ""
                if points != 0 or expect[fig] not in shown:
                    fail(f"{path}: fig {fid} of {serial['serial']}: {points} points, note "
                         f"{shown!r}; expected no points and the reason {expect[fig]!r}")
                if el.find_element(By.CSS_SELECTOR, ".chart").is_displayed():
                    fail(f"{path}: fig {fid} is not computed but shows an empty chart")
                print(f"fig {fid}: not computed, says {shown!r}")
                continue
            deadline = time.time() + 10
            while el.get_attribute("data-drawn") != "true" and time.time() < deadline:
                time.sleep(0.1)
            if points <= 0 or el.get_attribute("data-drawn") != "true" or \
                    not el.find_elements(By.CSS_SELECTOR, ".chart canvas"):
                fail(f"{path}: fig {fid} ({points} points) was not drawn")
            lab = labels.get(fid, {})
            for axis in ("x", "y"):
                if not UNIT.search(lab.get(axis) or "") or lab.get(axis) != lab.get("drawn" + axis):
                    fail(f"{path}: fig {fid} {axis} axis title {lab.get('drawn' + axis)!r} "
                         f"(figure's {lab.get(axis)!r}) does not name a unit")
            drawn.append(fid)
            print(f"fig {fid}: {points} points drawn, axes {lab['x']!r} / {lab['y']!r}")
    shot = os.path.join(artifacts, f"{name}-{slug}.png")
    drv.save_screenshot(shot)
    shoot_figures(drv, artifacts, f"{name}-{slug}")
    print(f"screenshot {shot}")
    check_ticks(drv, path, drawn)
    check_drawn(drv, path, fitted_curves=False)
    return drawn


def check_acceptance(drv, index, pages, report, artifacts, name):
    """The index links a page per acceptance kind; every page checked; every kind of figure
    drawn for at least one serial."""
    from selenium.webdriver.common.by import By
    load(drv, index)
    links = [a.get_attribute("href").rsplit("/", 1)[-1]
             for a in drv.find_elements(By.CSS_SELECTOR, "section.acceptance a")]
    run_id = report["run_id"]
    want = [f"run-{run_id}-{slug}.html" for slug in ACCEPTANCE_PAGES]
    if links != want:
        fail(f"{index}: acceptance links {links}, expected {want}")
    drawn = []
    for slug in ACCEPTANCE_PAGES:
        path = [p for p in pages if p.endswith(f"-{slug}.html")]
        if len(path) != 1:
            fail(f"report wrote {path} for the {slug} page")
        drawn += check_acceptance_page(drv, path[0], slug, report, artifacts, name)
    kinds = {d.split(".")[0] for d in drawn}
    missing = [f for figs in ACCEPTANCE_PAGES.values() for f in figs if f not in kinds]
    if missing:
        fail(f"figures {missing} drawn for no serial: the run does not exercise them")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--station", required=True)
    ap.add_argument("--work", required=True, help="scratch directory (database, report)")
    ap.add_argument("--artifacts", required=True, help="where the screenshot goes")
    ap.add_argument("--gyros", type=int, default=2)
    ap.add_argument("--ramps", action="store_true", help="also ramp_00/10/20 runs (Fig. 3)")
    ap.add_argument("--verify", action="store_true",
                    help="run --sim --verify: report the verification run (release, Fig. 6)")
    ap.add_argument("--acceptance", action="store_true",
                    help="a short acceptance protocol (acceptance_two_plateaus.toml): its pages")
    a = ap.parse_args()
    drv = browser()
    try:
        os.makedirs(a.work, exist_ok=True)
        os.makedirs(a.artifacts, exist_ok=True)
        name = ("report-ramps" if a.ramps else "report-verify" if a.verify else
                "report-acceptance" if a.acceptance else "report")
        db = os.path.join(a.work, name + ".db")
        t0 = time.time()
        report = make_db(a.station, db, a.gyros, a.ramps, a.verify,
                         ACCEPTANCE_PROTOCOL if a.acceptance else None)
        run_id = report["run_id"]
        print(f"database {db}: run {run_id} in {time.time() - t0:.1f} s")
        out_dir = os.path.join(a.work, name)
        shutil.rmtree(out_dir, ignore_errors=True)
        files = station(a.station, "report", "--db", db, "--run", str(run_id), "--out",
                        out_dir).split()
        index, pages = files[0], files[1:1 + a.gyros]
        if len(files) != 1 + a.gyros + (len(ACCEPTANCE_PAGES) if a.acceptance else 0):
            fail(f"expected {a.gyros} serial pages (and the acceptance pages), got {files[1:]}")
        load(drv, index)
        from selenium.webdriver.common.by import By
        links = drv.find_elements(By.CSS_SELECTOR, ".serials a")
        if len(links) != a.gyros:
            fail(f"{index}: {len(links)} serial links, expected {a.gyros}")
        if a.acceptance:
            check_acceptance(drv, index, files[1 + a.gyros:], report, a.artifacts, name)
            load(drv, index)
        elif drv.find_elements(By.CSS_SELECTOR, "section.acceptance"):
            fail(f"{index}: a run without acceptance steps links acceptance pages")
        check_clean(drv, index)
        check_units(drv, index)
        load(drv, pages[0])
        check_figures(drv, pages[0], a.ramps)
        check_clean(drv, pages[0])
        check_units(drv, pages[0])
        shot = os.path.join(a.artifacts, name + ".png")
        drv.save_screenshot(shot)
        # The figures alone (docs/report.png is one of these); kept before the tick check, so a
        # failing check leaves the picture of what failed.
        figures = os.path.join(a.artifacts, name + "-figures.png")
        drv.find_element(By.CSS_SELECTOR, ".figures").screenshot(figures)
        print(f"screenshots {shot} {figures}")
        check_ticks(drv, pages[0], [f for f in FIGURES if a.ramps or f != "3"])
        check_drawn(drv, pages[0])
        shoot_figures(drv, a.artifacts, name)
        if a.verify:
            fig6 = check_verification(drv, index, pages[0], report)
            verification = os.path.join(a.artifacts, name + "-verification.png")
            drv.find_element(By.CSS_SELECTOR, "section.verification").screenshot(verification)
            print(f"screenshot {verification}")
            check_units(drv, pages[0])
            check_ticks(drv, pages[0], ["6"])
            check_drawn(drv, pages[0])
            # The calibration run's page: its fit is the released one.
            cal_dir = out_dir + "-calibration"
            shutil.rmtree(cal_dir, ignore_errors=True)
            cal = station(a.station, "report", "--db", db, "--run",
                          str(report["calibration_run"]["run_id"]), "--out", cal_dir).split()
            load(drv, cal[1])
            rel = drv.find_element(By.CSS_SELECTOR, "p.release").text
            if not rel.startswith("RELEASED"):
                fail(f"{cal[1]}: the calibration run's fit is not shown released: {rel!r}")
        if not a.ramps and not a.acceptance:
            check_pdf(a.station, db, run_id, out_dir + "-pdf", a.gyros)
    finally:
        drv.quit()
    print("PASS")


if __name__ == "__main__":
    main()
