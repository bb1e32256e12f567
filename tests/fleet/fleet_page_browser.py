#!/usr/bin/env python3
"""Two stations, one PostgreSQL: two simulated runs of the same gyros (station files a.db and
b.db, renamed rig-a and rig-b, judged against the example part file), forwarded with `station
sync`; then what the fleet reads back:

  fleet_page_browser.py STATION ARTIFACT_DIR SHORT_CYCLE_TOML PARTS_TOML

Checks: `history --pg` shows each gyro's fits from both stations, naming them, with the fits the
two files hold; `station fleet --json` has one chart per metric with limits and every
calibration; the page DIR/fleet.html in headless Chromium draws every figure, logs no console
error, and its tick labels are readable (no duplicate on an axis, no two overlapping, none cut);
screenshot ARTIFACT_DIR/fleet_page.png.

Issue 36, the acceptance figures: two more stations (rig-c, rig-d) run tests/fleet/
acceptance_two_ladders.toml on two GX-200 gyros each (K at 25 C and its temperature coefficient,
no fit); rig-d's second result is made one whose ladders were not computed. `station fleet
--json` charts K and TC per part with each result's stored value and SE, the missing one with its
reason and no point; the text output names it; on the page both figures are drawn with error bars
and readable ticks, the results table has units and says why; screenshot
ARTIFACT_DIR/fleet-acceptance.png. Exit 0 ok, 1 failure, 77 skip.
"""
import json
import os
import shutil
import sqlite3
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "report"))
import pg_server  # noqa: E402
import report_browser  # noqa: E402  (the report's tick and unit checks: one rule for both)

ACCEPTANCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "acceptance_two_ladders.toml")
NOT_COMPUTED = "3 of 4 points not measured"

FAILURES = []


def check(cond, what):
    if not cond:
        FAILURES.append(what)
        print("FAIL:", what, flush=True)
    return cond


def run(*args, cwd=None):
    r = subprocess.run(list(args), cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit("failed (%d): %s\n%s" % (r.returncode, " ".join(args), r.stderr))
    return r.stdout


def browser():
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        return None, "python3-selenium is not importable (Debian: python3-selenium)"
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if not chromium or not driver:
        return None, "chromium and chromedriver are needed (Debian: chromium chromium-driver)"
    opts = webdriver.ChromeOptions()
    opts.binary_location = chromium
    for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1400,1700",
              "--disable-dev-shm-usage"]:
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(executable_path=driver), options=opts), None


def acceptance_stations(station, parts, pg, work):
    """rig-c and rig-d: an acceptance run each, forwarded; rig-d's second result made one whose
    ladders were not computed (as `fit --acceptance` stores it: no K, no TC, each ladder's error).
    Returns the stored rows (station, serial, K, K's SE, K's temperature, TC, TC's SE)."""
    stored = []
    for name, seed in (("c", "7"), ("d", "8")):
        run(station, "run", "--sim", "--db", name + ".db", "--protocol", ACCEPTANCE, "--gyros", "2",
            "--seed", seed, "--parts", parts, "--part", "GX-200", cwd=work)
        db = sqlite3.connect(os.path.join(work, name + ".db"))
        db.execute("UPDATE runs SET station = ?", ("rig-" + name,))
        if name == "d":
            serial, figures = db.execute("SELECT serial, figures_json FROM acceptance_results "
                                         "ORDER BY rowid DESC LIMIT 1").fetchone()
            f = json.loads(figures)
            f["ladders"] = [{"label": x["label"], "ok": False, "error": NOT_COMPUTED}
                            for x in f["ladders"]]
            f.pop("sf_vs_temp", None)
            db.execute("UPDATE acceptance_results SET figures_json = ?, sf_pulse_per_arcsec = NULL, "
                       "sf_se_pulse_per_arcsec = NULL, sf_temp_c = NULL, tc_ppm_per_c = NULL, "
                       "tc_se_ppm_per_c = NULL WHERE serial = ?", (json.dumps(f), serial))
        db.commit()
        stored += [("rig-" + name,) + tuple(r) for r in db.execute(
            "SELECT serial, sf_pulse_per_arcsec, sf_se_pulse_per_arcsec, sf_temp_c, tc_ppm_per_c, "
            "tc_se_ppm_per_c FROM acceptance_results ORDER BY rowid")]
        db.close()
        run(station, "sync", "--db", name + ".db", "--pg", pg.url(), cwd=work)
    return stored


def check_acceptance_json(charts, stored):
    """`station fleet --json`'s "acceptance": part GX-200, every stored result in run order, K and
    TC points exactly the stored values and SEs, K held at 25 C, the missing one with its why."""
    parts = charts.get("acceptance", {}).get("parts", [])
    if not check(len(parts) == 1 and parts[0]["part"] == "GX-200",
                 "acceptance charted for part GX-200: %s" % [p.get("part") for p in parts]):
        return
    part = parts[0]
    results = part["results_list"]
    check([(r["station"], r["serial"]) for r in results] == [(s[0], s[1]) for s in stored],
          "every result, in the order the runs started: %s" % [(r["station"], r["serial"])
                                                               for r in results])
    k, tc = part["charts"]
    check(k["unit"] == "pulse/arcsec" and tc["unit"] == "ppm/C", "units: %s, %s" %
          (k["unit"], tc["unit"]))
    want_k = [(i + 1, s[2], s[3]) for i, s in enumerate(stored) if s[2] is not None]
    check([(p["x"], p["value"], p["se"]) for p in k["points"]] == want_k,
          "K points are the stored K and SE: %s" % k["points"])
    check(all(p["held_temp_c"] == 25.0 for p in k["points"]), "K held at 25 C")
    want_tc = [(i + 1, s[5], s[6]) for i, s in enumerate(stored) if s[5] is not None]
    check([(p["x"], p["value"], p["se"]) for p in tc["points"]] == want_tc,
          "TC points are the stored TC and SE: %s" % tc["points"])
    missing = [r for r in results if r["sf_missing"]]
    check(len(missing) == 1 and NOT_COMPUTED in missing[0]["sf_missing"] and
          missing[0]["sf_pulse_per_arcsec"] is None,
          "one result without K, its reason and no zero: %s" % missing)
    check(k["overall"] and k["overall"]["lcl"] < k["overall"]["centre"] < k["overall"]["ucl"],
          "K limits around the centre: %s" % k["overall"])


def check_acceptance_page(driver, charts, artifacts):
    """The acceptance section: both figures drawn with a whisker per point, the table's missing
    K said in words; screenshot."""
    secs = driver.find_elements("css selector", "section.acceptance")
    if not check(len(secs) == 1, "one acceptance section: %d" % len(secs)):
        return
    whiskers = driver.execute_script(
        "var f = JSON.parse(document.getElementById('report-figures').textContent);"
        "return f.filter(function (x) { return x.id.indexOf('acceptance-') === 0; }).map("
        "function (x) { return [x.id, x.rows.filter(function (r) { return r.slice(1).some("
        "function (v) { return Array.isArray(v) && v[0] < v[1] && v[1] < v[2]; }); }).length]; });")
    part = charts["acceptance"]["parts"][0]
    want = [["acceptance-%s-1" % c["metric"], len(c["points"])] for c in part["charts"]]
    check(whiskers == want, "every acceptance point has its error bar: %s, want %s" %
          (whiskers, want))
    table = secs[0].find_element("css selector", "table.acceptance-results").text
    check(("not computed: scale factor, room: " + NOT_COMPUTED) in table,
          "the results table says why K is missing")
    os.makedirs(artifacts, exist_ok=True)
    secs[0].screenshot(os.path.join(artifacts, "fleet-acceptance.png"))


def main():
    why = pg_server.unavailable()
    if why:
        print("SKIP:", why)
        return 77
    station, artifacts, cycle, parts = [os.path.abspath(a) for a in sys.argv[1:5]]
    work = tempfile.mkdtemp(prefix="fleet-page-")
    pg = pg_server.Postgres()
    try:
        for name, seed in (("a", "5"), ("b", "6")):
            run(station, "run", "--sim", "--db", name + ".db", "--protocol", cycle, "--gyros", "3",
                "--seed", seed, "--parts", parts, cwd=work)
            db = sqlite3.connect(os.path.join(work, name + ".db"))
            db.execute("UPDATE runs SET station = ?", ("rig-" + name,))
            db.commit()
            db.close()
            run(station, "sync", "--init", "--db", name + ".db", "--pg", pg.url(), cwd=work)
        serial = sqlite3.connect(os.path.join(work, "a.db")).execute(
            "SELECT serial FROM run_slots ORDER BY slot LIMIT 1").fetchone()[0]
        h = json.loads(run(station, "history", "--pg", pg.url(), "--serial", serial, "--json"))
        local = sum(sqlite3.connect(os.path.join(work, n + ".db")).execute(
            "SELECT count(*) FROM fits WHERE serial = ?", (serial,)).fetchone()[0] for n in "ab")
        check(len(h["fits"]) == local and local >= 2,
              "history --pg: %d fits of %s, the files hold %d" % (len(h["fits"]), serial, local))
        check({f["station"] for f in h["fits"]} == {"rig-a", "rig-b"},
              "history --pg names both stations: %s" % {f["station"] for f in h["fits"]})
        check({r["station"] for r in h["runs"]} == {"rig-a", "rig-b"}, "runs of both stations")
        # One calibration of another model (dT: no k0) at rig-a: a chart set of its own with
        # one point per chart and no k0 chart.
        run(station, "fit", "--db", "a.db", "--serial", serial, "--terms", "dT", cwd=work)
        run(station, "sync", "--db", "a.db", "--pg", pg.url(), cwd=work)
        stored = acceptance_stations(station, parts, pg, work)

        out = os.path.join(work, "fleet")
        charts = json.loads(run(station, "fleet", "--pg", pg.url(), "--out", out, "--json"))
        check(len(charts["parts"]) >= 1, "a part charted: %s" % charts)
        single = [p for p in charts["parts"] if p["terms"] == "dT"]
        check(len(single) == 1 and single[0]["calibrations"] == 1 and
              not single[0]["charts"][1]["points"],
              "one calibration of model dT (no gradT), no k0: %s" % [(p["terms"], p["calibrations"])
                                                           for p in charts["parts"]])
        check_acceptance_json(charts, stored)
        text = run(station, "fleet", "--pg", pg.url())
        check("K not computed: rig-d %s" % stored[-1][1] in text and NOT_COMPUTED in text,
              "the text output names the result without K and why: %s" % text[-600:])
        for part in charts["parts"]:
            if part in single:
                continue
            metrics = [c["metric"] for c in part["charts"]]
            check(metrics == ["k1", "k0", "B0", "std_ratio"], "the four charts: %s" % metrics)
            k1 = part["charts"][0]
            check(k1["overall"] and k1["overall"]["lcl"] < k1["overall"]["centre"] <
                  k1["overall"]["ucl"], "k1 limits around the centre: %s" % k1["overall"])
            check(len(k1["points"]) == part["calibrations"] == 6,
                  "six calibrations (3 gyros x 2 stations): %d" % len(k1["points"]))
            check(set(part["verdicts"]) == {"rig-a", "rig-b"}, "verdicts per station")

        driver, why = browser()
        if driver is None:
            print("SKIP (browser part):", why)
            return 77 if not FAILURES else 1
        try:
            driver.get("file://" + os.path.join(out, "fleet.html"))
            from selenium.webdriver.support.ui import WebDriverWait
            WebDriverWait(driver, 20).until(lambda d: d.execute_script(
                "return document.querySelectorAll('[data-figure]').length > 0 && "
                "document.querySelectorAll('[data-figure]:not([data-drawn])').length === 0"))
            ids = ["%s-%d" % (c["metric"], i + 1) for i, p in enumerate(charts["parts"])
                   for c in p["charts"] if c["points"]]
            ids += ["acceptance-%s-%d" % (c["metric"], i + 1)
                    for i, p in enumerate(charts["acceptance"]["parts"]) for c in p["charts"]]
            try:
                report_browser.check_ticks(driver, "fleet.html", ids)
                report_browser.check_units(driver, "fleet.html")
                # Every point inside its plot area: one calibration in the middle, not on the axis.
                report_browser.check_drawn(driver, "fleet.html", fitted_curves=False)
            except SystemExit:  # report_browser.fail printed what failed
                check(False, "fleet.html: the report's tick, unit or drawn-point checks")
            one = charts["parts"].index(single[0]) + 1 if single else 0
            check(not driver.find_elements("css selector", '[data-figure="k0-%d"]' % one),
                  "no empty k0 chart for model dT")
            sec = [e for e in driver.find_elements("css selector", "section.part")
                   if e.find_elements("css selector", '.no-chart[data-metric="k0"]')]
            check(len(sec) == 1 and "one calibration" in sec[0].text,
                  "the dT set says 'one calibration' and why k0 has no chart")
            if sec:
                os.makedirs(artifacts, exist_ok=True)
                sec[0].screenshot(os.path.join(artifacts, "fleet-one-calibration.png"))
            check_acceptance_page(driver, charts, artifacts)
            severe = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
            check(not severe, "no console error: %s" % severe)
            os.makedirs(artifacts, exist_ok=True)
            driver.save_screenshot(os.path.join(artifacts, "fleet_page.png"))
        finally:
            driver.quit()
    finally:
        pg.close()
    if FAILURES:
        print("%d failure(s)" % len(FAILURES))
        return 1
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
