#!/usr/bin/env python3
"""Two stations, one PostgreSQL: two simulated runs of the same gyros (station files a.db and
b.db, renamed rig-a and rig-b, judged against the example part file), forwarded with `station
sync`; then what the fleet reads back:

  fleet_page_browser.py STATION ARTIFACT_DIR SHORT_CYCLE_TOML PARTS_TOML

Checks: `history --pg` shows each gyro's fits from both stations, naming them, with the fits the
two files hold; `station fleet --json` has one chart per metric with limits and every
calibration; the page DIR/fleet.html in headless Chromium draws every figure, logs no console
error, and its tick labels are readable (no duplicate on an axis, no two overlapping, none cut);
screenshot ARTIFACT_DIR/fleet_page.png. Exit 0 ok, 1 failure, 77 skip.
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

        out = os.path.join(work, "fleet")
        charts = json.loads(run(station, "fleet", "--pg", pg.url(), "--out", out, "--json"))
        check(len(charts["parts"]) >= 1, "a part charted: %s" % charts)
        single = [p for p in charts["parts"] if p["terms"] == "dT"]
        check(len(single) == 1 and single[0]["calibrations"] == 1 and
              not single[0]["charts"][1]["points"],
              "one calibration of model dT (no gradT), no k0: %s" % [(p["terms"], p["calibrations"])
                                                           for p in charts["parts"]])
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
