#!/usr/bin/env python3
"""After a run, its results where the operator looks (issue 35): the live page's results panel
and the report the API serves, in headless Chromium (Selenium + chromedriver) and a plain HTTP
client.

A short simulated run (`run --sim`, tests/data/short_cycle.toml, a part file) fills a database;
`station serve` on simrig then serves it. Checks: GET /api/runs/1 carries each fit's verdict,
its text and the report link; GET /reports/run-1.html and a serial's page (linked from it) are the
report's pages, and an unknown page is a 404 naming it; the live page shows a results panel with
one row per serial whose k1 ± SE, k0 ± SE, B0, std ratio, verdict and model are the API's; the
report opened from the panel's link draws its figures (its inline script runs under its own
Content-Security-Policy); no console error. Keeps a screenshot (ARTIFACT_DIR/live_after_run.png).

Usage: live_results_browser.py STATION SIMRIG ARTIFACT_DIR SHORT_CYCLE
Exit 0 pass, 1 fail, 77 skip (Chromium, chromedriver or python3-selenium absent).
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "report"))
import report_browser  # noqa: E402  (the shared headless Chromium)

PARTS = '[part."WIDE"]\nB0_dph = { min = -1000.0, max = 1000.0 }\n'


class Failure(Exception):
    pass


def check(cond, what):
    if not cond:
        raise Failure(what)


def browser():
    """The report tests' headless Chromium (tests/report/report_browser.py: it skips with 77 when
    selenium or chromium is missing), in a window the size of docs/live_after_run.png."""
    drv = report_browser.browser()
    drv.set_window_size(1400, 1100)
    return drv


def get(base, path):
    """(status, content type, body text) of a GET, as any HTTP client sees it."""
    try:
        with urllib.request.urlopen(base + path, timeout=30) as r:
            return r.status, r.headers.get("Content-Type", ""), r.read().decode()
    except urllib.error.HTTPError as e:
        return e.code, e.headers.get("Content-Type", ""), e.read().decode()


def wait_for(pred, timeout_s, what):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        v = pred()
        if v:
            return v
        time.sleep(0.2)
    raise Failure("timed out waiting for " + what)


def js_exp(v, digits):
    """JavaScript's Number.prototype.toExponential: 1.234e-3, not Python's 1.234e-03."""
    mantissa, exp = f"{v:.{digits}e}".split("e")
    return f"{mantissa}e{int(exp):+d}".replace("e+", "e+")


def with_error(fit, name):
    if name not in fit["coefficients"]:
        return "—"
    return js_exp(fit["coefficients"][name], 3) + " ± " + js_exp(fit["std_errors"][name], 1)


def simulate(station, work, protocol):
    with open(os.path.join(work, "parts.toml"), "w") as f:
        f.write(PARTS)
    r = subprocess.run([station, "run", "--sim", "--gyros", "2", "--seed", "3", "--db", "s.db",
                        "--protocol", protocol, "--parts", "parts.toml"], cwd=work,
                       capture_output=True, text=True, timeout=600)
    check(r.returncode == 0, "run --sim failed: " + r.stdout + r.stderr)
    print(r.stdout)


def start_services(station, simrig, work):
    rig = subprocess.Popen([simrig, "--gyros", "2", "--can-socket", os.path.join(work, "can.sock")],
                           stdout=open(os.path.join(work, "rig.toml"), "w"),
                           stderr=subprocess.DEVNULL, cwd=work)
    wait_for(lambda: os.path.getsize(os.path.join(work, "rig.toml")) > 200, 10, "simrig")
    time.sleep(0.3)
    serve = subprocess.Popen([station, "serve", "--config", "rig.toml", "--db", "s.db", "--http",
                              "127.0.0.1:0"], cwd=work, stdout=subprocess.PIPE,
                             stderr=open(os.path.join(work, "serve.log"), "w"), text=True)
    line = serve.stdout.readline()
    check(line.startswith("http: listening on "), "serve did not print its address: %r" % line)
    return [rig, serve], line.split()[-1].rstrip("/")


def check_api(base):
    status, _, body = get(base, "/api/runs/1")
    check(status == 200, "GET /api/runs/1: %d %s" % (status, body))
    run = json.loads(body)
    check(run["report"] == "/reports/run-1.html", "report link: %r" % run.get("report"))
    for s in run["slots"]:
        f = s["fit"]
        check(f is not None, "slot %d has no fit" % s["slot"])
        check(f["part_number"] == "WIDE" and f["verdict"]["pass"] is True, "verdict: %r" % f)
        check(f["verdict_text"].startswith("pass (part WIDE"), "verdict_text: %r" % f)
    status, ctype, index = get(base, run["report"])
    check(status == 200 and ctype.startswith("text/html"), "GET %s: %d %s" % (run["report"],
                                                                             status, ctype))
    for s in run["slots"]:
        check(s["serial"] in index, "the report's index names %s" % s["serial"])
    page = page_of(run)
    check('href="%s"' % page in index, "the index links %s" % page)
    status, ctype, text = get(base, "/reports/" + page)
    check(status == 200 and 'id="report-figures"' in text, "GET /reports/%s: %d" % (page, status))
    for bad in ["run-99.html", "run-1-slot9-X.html", "run-01.html", "passwd"]:
        status, ctype, text = get(base, "/reports/" + bad)
        check(status == 404 and "error" in json.loads(text), "GET /reports/%s: %d %s"
              % (bad, status, text))
    return run


def page_of(run):
    """The report page of the run's first slot (the stored slot index in its name)."""
    return "run-1-slot%d-%s.html" % (run["slots"][0]["slot"], run["slots"][0]["serial"])


def check_page(drv, base, run, artifacts):
    from selenium.webdriver.common.by import By
    drv.get(base + "/")
    wait_for(lambda: drv.find_element(By.ID, "results").is_displayed(), 20, "the results panel")
    rows = wait_for(lambda: drv.find_elements(By.CSS_SELECTOR, "#results-rows tr"), 10, "rows")
    check(len(rows) == len(run["slots"]), "%d rows for %d slots" % (len(rows), len(run["slots"])))
    for tr, s in zip(rows, run["slots"]):
        f = s["fit"]
        cells = [td.text for td in tr.find_elements(By.TAG_NAME, "td")]
        want = [str(s["slot"] + 1), s["serial"], with_error(f, "k1"), with_error(f, "k0"),
                js_exp(f["coefficients"]["B0"], 3), "%.3f" % f["std_ratio"], f["verdict_text"],
                f["terms"]]
        check(cells == want, "row of %s: %r, the API says %r" % (s["serial"], cells, want))
    link = drv.find_element(By.ID, "results-report")
    check(link.get_attribute("href") == base + "/reports/run-1.html", "link %s"
          % link.get_attribute("href"))
    os.makedirs(artifacts, exist_ok=True)
    drv.save_screenshot(os.path.join(artifacts, "live_after_run.png"))
    severe = [e for e in drv.get_log("browser") if e["level"] == "SEVERE"]
    check(not severe, "console errors on the live page: %r" % severe)
    drv.get(base + "/reports/" + page_of(run))
    drawn = wait_for(lambda: drv.find_elements(By.CSS_SELECTOR, '[data-figure][data-drawn="true"]'),
                     30, "a drawn figure in the served report")
    check(len(drawn) >= 3, "%d figures drawn in the served report" % len(drawn))
    severe = [e for e in drv.get_log("browser") if e["level"] == "SEVERE"]
    check(not severe, "console errors on the served report: %r" % severe)


def main():
    station, simrig, artifacts, protocol = [os.path.abspath(a) for a in sys.argv[1:5]]
    drv = browser()
    work = tempfile.mkdtemp(prefix="live-results-")
    procs = []
    try:
        simulate(station, work, protocol)
        procs, base = start_services(station, simrig, work)
        run = check_api(base)
        check_page(drv, base, run, artifacts)
        print("PASS")
        return 0
    except Failure as e:
        print("FAIL:", e)
        return 1
    finally:
        drv.quit()
        for p in reversed(procs):
            p.terminate()
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
