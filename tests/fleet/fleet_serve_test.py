#!/usr/bin/env python3
"""`station serve` with [fleet] on simrig, forwarding to a throw-away PostgreSQL 15 while a run
goes on at 1 Hz on the wall clock; PostgreSQL stopped in the middle of the run and started again.

  fleet_serve_test.py STATION SIMRIG [ARTIFACT_DIR]

Checks: the forwarder reports itself in /api/status and /metrics; while the server is down it
backs off, the backlog grows and the run goes on, and the live page (headless Chromium) shows
it; when the server returns the backlog drains;
after the run every sample and event of the run is in PostgreSQL exactly once and the run's
central state is its final one; no tick was slowed (the tick histogram has no tick over 0.25 s
and no tick was missed). Then the forwarder's backend is frozen (SIGSTOP): the status and
/metrics say it waits on the server, and SIGTERM ends serve within the unit's TimeoutStopSec. Exit 0 ok, 1 failure, 77 skip (no PostgreSQL 15 server binaries).
"""
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "web"))
import pg_server  # noqa: E402
from serve_http_test import check, FAILURES, request, wait_for, start_serve, status  # noqa: E402


def metric(base, name):
    import urllib.request
    text = urllib.request.urlopen(base + "/metrics", timeout=10).read().decode()
    values = {}
    for line in text.splitlines():
        if line.startswith(name):
            key, _, value = line.rpartition(" ")
            values[key] = float(value)
    return values


def page_shows_fleet(base, artifacts):
    """The live page in headless Chromium shows the forwarder backing off (skipped, with a
    message, without a browser)."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__))))
    from fleet_page_browser import browser
    driver, why = browser()
    if driver is None:
        print("SKIP (live page part):", why)
        return
    try:
        from selenium.webdriver.support.ui import WebDriverWait
        driver.get(base + "/")
        shown = WebDriverWait(driver, 20).until(lambda d: d.execute_script(
            "var e = document.getElementById('fleet'); return e && "
            "!document.getElementById('fleet-box').hidden && e.textContent.indexOf('backing off') "
            "=== 0 ? e.textContent : null"))
        check(shown and "rows pending" in shown, "the live page shows the backlog: %r" % shown)
        tip = driver.execute_script("return document.getElementById('fleet').title")
        check("PostgreSQL" in tip, "the last error as the tooltip: %r" % tip)
        if artifacts:
            os.makedirs(artifacts, exist_ok=True)
            driver.save_screenshot(os.path.join(artifacts, "live_page_fleet.png"))
    finally:
        driver.quit()


def stop_timeout_s():
    """systemd's TimeoutStopSec of the shipped unit: how long a stop may take before SIGKILL."""
    unit = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "station",
                        "package", "gyro-station.service")
    for line in open(unit):
        if line.startswith("TimeoutStopSec="):
            return float(line.split("=", 1)[1])
    raise RuntimeError("no TimeoutStopSec in " + unit)


def frozen_backend_then_stop(pg, serve, base):
    """Issue 34 point 5: the forwarder's backend stopped (SIGSTOP: its connection stays up). The
    status and /metrics say the forwarder waits on the server (not idle), the metrics still lint,
    and SIGTERM ends serve within the unit's stop timeout while the backend is still frozen."""
    pids = [int(p) for p in pg.query("SELECT pid FROM pg_stat_activity WHERE application_name "
                                     "= 'gyro-station'").split()]
    check(len(pids) == 1, "one forwarder connection: %s" % pids)
    for pid in pids:
        os.kill(pid, signal.SIGSTOP)
    try:
        f = wait_for(lambda: (lambda f: f if f["state"] == "waiting on server" else None)(
            status(base)["fleet"]), 20, "the status saying the forwarder waits on the server")
        check(f and f["waiting_s"] >= 1 and f["waiting_for"], "what it waits for: %s" % f)
        check(metric(base, "station_fleet_state").get(
            'station_fleet_state{state="waiting on server"}') == 1, "the state in /metrics")
        check(max(metric(base, "station_fleet_waiting_seconds").values()) >= 1,
              "the wait in /metrics")
        promtool = shutil.which("promtool")
        if promtool:
            import urllib.request
            text = urllib.request.urlopen(base + "/metrics", timeout=10).read()
            p = subprocess.run([promtool, "check", "metrics"], input=text, capture_output=True)
            check(p.returncode == 0, "promtool check metrics: %s" % p.stderr.decode())
        serve.send_signal(signal.SIGTERM)
        try:
            rc = serve.wait(timeout=stop_timeout_s())
            check(rc == 0, "serve stopped with %d" % rc)
        except subprocess.TimeoutExpired:
            check(False, "serve still running %.0f s after SIGTERM (the unit's stop timeout) "
                  "with its PostgreSQL backend frozen" % stop_timeout_s())
    finally:
        for pid in pids:
            os.kill(pid, signal.SIGCONT)


def local(work, sql, *args):
    db = sqlite3.connect(os.path.join(work, "s.db"))
    try:
        return db.execute(sql, args).fetchone()
    finally:
        db.close()


def main():
    why = pg_server.unavailable()
    if why:
        print("SKIP:", why)
        return 77
    station, simrig = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    artifacts = os.path.abspath(sys.argv[3]) if len(sys.argv) > 3 else None
    work = tempfile.mkdtemp(prefix="fleet-serve-")
    pg = pg_server.Postgres()
    rig_cfg = open(os.path.join(work, "rig.toml"), "w")
    rig = subprocess.Popen([simrig, "--gyros", "2", "--control", os.path.join(work, "ctl"),
                            "--can-socket", os.path.join(work, "can.sock")],
                           stdout=rig_cfg, stderr=subprocess.DEVNULL, cwd=work)
    procs = [rig]
    try:
        wait_for(lambda: os.path.getsize(os.path.join(work, "rig.toml")) > 200, 10, "simrig")
        time.sleep(0.3)
        with open(os.path.join(work, "rig.toml"), "a") as f:
            f.write('\n[fleet]\npg = "%s"\nsamples = true\ninterval_s = 0.5\n' % pg.url())
        # The central schema, once, before the station has a file.
        out = subprocess.run([station, "sync", "--init", "--config", "rig.toml"],
                             cwd=work, capture_output=True, text=True)
        check(out.returncode == 0, "sync --init: %s" % out.stderr)
        serve, base = start_serve(station, work, "serve.log")
        procs.append(serve)
        token = open(os.path.join(work, "s.db.token")).read().strip()
        st = wait_for(lambda: (lambda s: s if s.get("fleet") else None)(status(base)), 10,
                      "the forwarder's state in /api/status")
        check(st and st["fleet"]["state"] in ("idle", "sending"), "forwarder up: %s" % st)
        code, body = request(base, "POST", "/api/runs", token, {"protocol": "paper"})
        check(code == 202, "start: %d %s" % (code, body))
        run = body.get("run_id", -1)
        wait_for(lambda: status(base)["ticks"] >= 8, 20, "eight ticks")
        wait_for(lambda: int(pg.query("SELECT count(*) FROM samples") or 0) > 0, 15,
                 "samples arriving while the run goes on")

        pg.stop()
        st = wait_for(lambda: (lambda s: s if s["fleet"]["state"] == "backing off" else None)(
            status(base)), 20, "the forwarder backing off")
        ticks_down = status(base)["ticks"]
        time.sleep(8)
        st = status(base)
        check(st["ticks"] >= ticks_down + 6, "the run goes on while PostgreSQL is down: %d -> %d"
              % (ticks_down, st["ticks"]))
        check(st["fleet"]["pending_rows"] > 0, "a backlog while down: %s" % st["fleet"])
        check(st["fleet"]["backoff_s"] >= 1.0, "the back-off grew: %s" % st["fleet"])
        page_shows_fleet(base, artifacts)
        m = metric(base, "station_fleet_pending_rows")
        check(m and max(m.values()) > 0, "backlog in /metrics: %s" % m)
        errors = metric(base, "station_fleet_errors_total")
        check(errors and max(errors.values()) >= 2, "failures counted: %s" % errors)

        pg.start()
        # Drained: caught up to within a few ticks of the running run (2 gyros, a pass every
        # 0.5 s; what the last ticks added since the pass is all that may be pending).
        backlog = st["fleet"]["pending_rows"]
        wait_for(lambda: (lambda f: f["state"] != "backing off" and f["pending_rows"] <= 20)(
            status(base)["fleet"]), 90, "the backlog (%d rows) drained after PostgreSQL returned"
            % backlog)
        code, _ = request(base, "POST", "/api/runs/%d/stop" % run, token)
        check(code == 202, "stop: %d" % code)
        wait_for(lambda: status(base)["state"] == "idle", 20, "idle after stop")
        wait_for(lambda: pg.query("SELECT state FROM runs") == "stopped", 30,
                 "the run's final state forwarded")
        wait_for(lambda: status(base)["fleet"]["pending_items"] == 0, 30, "nothing pending")

        n_local = local(work, "SELECT count(*) FROM samples WHERE run_id = ?", run)[0]
        e_local = local(work, "SELECT count(*) FROM events WHERE run_id = ?", run)[0]
        check(int(pg.query("SELECT count(*) FROM samples")) == n_local,
              "every sample once: %s central, %d local" % (pg.query("SELECT count(*) FROM samples"),
                                                           n_local))
        check(int(pg.query("SELECT count(*) FROM events")) == e_local,
              "every event once: %s central, %d local" % (pg.query("SELECT count(*) FROM events"),
                                                          e_local))
        check(pg.query("SELECT count(*) FROM (SELECT serial, t_s FROM samples GROUP BY 1, 2 "
                       "HAVING count(*) > 1) AS d") == "0", "no sample twice")
        missed = metric(base, "station_missed_ticks_total")
        check(missed and max(missed.values()) == 0, "no missed tick: %s" % missed)
        h = metric(base, "station_tick_duration_seconds_bucket")
        slow = [k for k in h if 'le="0.25"' in k]
        total = [k for k in h if 'le="+Inf"' in k]
        check(slow and total and h[slow[0]] == h[total[0]],
              "every tick under 0.25 s while the server went away and came back: %s" % h)
        frozen_backend_then_stop(pg, serve, base)
    finally:
        for p in procs:
            p.kill()
            p.wait()
        pg.close()
    if FAILURES:
        print("%d failure(s)" % len(FAILURES))
        return 1
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
