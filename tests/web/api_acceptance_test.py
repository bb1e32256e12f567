#!/usr/bin/env python3
"""GET /api/runs/{id}/acceptance (schemas/api.md, issue 36) with a plain HTTP client.

A completed acceptance run (`station run --sim --protocol tests/data/acceptance_short.toml
--gyros 2 --parts example_parts.toml --part GX-200 --json`), then a daemon serving the same
database (`run --sim --speed 200 --new --http 127.0.0.1:0`, as api_http_test.py's scenario R):
- the finished run's figures: 200, "serials" exactly the rows the run's end stored
  (acceptance_results.figures_json, in slot order) and the figures `run --json` printed (the
  simulated truth left out), each serial with its verdict against GX-200, "computed_utc" the rows';
- the run in progress (no acceptance step, not ended): 200, no serials, "computed_utc" null;
- an unknown run 404, a malformed id 400, each with the contract's {"error": ...} body.

Usage: api_acceptance_test.py STATION_BINARY       exit 0 pass, 1 fail, 77 skipped (no python3)
"""
import json
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import api_http_test as api  # noqa: E402  (the daemon, HTTP and check helpers)

HERE = os.path.dirname(os.path.abspath(__file__))
PROTOCOL = os.path.join(HERE, "..", "data", "acceptance_short.toml")
PARTS = os.path.join(HERE, "..", "..", "station", "parts", "example_parts.toml")


def without_truth(v):
    """run --sim's figures with the simulated truth ("true", at any depth) left out."""
    if isinstance(v, dict):
        return {k: without_truth(x) for k, x in v.items() if k != "true"}
    if isinstance(v, list):
        return [without_truth(x) for x in v]
    return v


def stored_rows(db, run_id):
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    try:
        return con.execute("SELECT serial, computed_utc, figures_json FROM acceptance_results "
                           "WHERE run_id = ? ORDER BY rowid", (run_id,)).fetchall()
    finally:
        con.close()


def check_finished(port, db, run_id, printed):
    r, body = api.get_json(port, f"/api/runs/{run_id}/acceptance")
    if not api.check(r.status == 200 and isinstance(body, dict),
                     f"GET /api/runs/{run_id}/acceptance: 200 with an object", r.brief()):
        return
    rows = stored_rows(db, run_id)
    api.check(len(rows) == 2, "the run's end stored a row per gyro", f"{len(rows)} rows")
    api.check(body.get("run_id") == run_id, "run_id is the run's", str(body.get("run_id")))
    serials = body.get("serials")
    api.check(serials == [json.loads(f) for _, _, f in rows],
              "serials: exactly the stored figures, in slot order", json.dumps(serials)[:300])
    api.check(serials == without_truth(printed),
              "serials: the figures `run --json` printed (without the simulated truth)")
    api.check(rows and body.get("computed_utc") == rows[0][1], "computed_utc: the rows'",
              f"{body.get('computed_utc')} vs {rows[0][1] if rows else None}")
    for s in serials or []:
        ladder = s["ladders"][0]
        api.check(ladder.get("ok") is True and api.is_num(ladder.get("sf_pulse_per_arcsec"))
                  and api.is_num(ladder.get("sf_se_pulse_per_arcsec")),
                  f"{s['serial']}: the ladder's scale factor with its standard error")
        v = s.get("verdict", {})
        api.check(v.get("part") == "GX-200" and isinstance(v.get("pass"), bool)
                  and isinstance(v.get("failed"), list),
                  f"{s['serial']}: a verdict against GX-200", json.dumps(v))


def check_running_and_bad(port, running_id):
    deadline = time.time() + 30  # the daemon listens before its run is in the database
    while api.request(port, "GET", f"/api/runs/{running_id}").status != 200 and \
            time.time() < deadline:
        time.sleep(0.1)
    r, body = api.get_json(port, f"/api/runs/{running_id}/acceptance")
    api.check(r.status == 200 and body == {"run_id": running_id, "computed_utc": None,
                                            "serials": []},
              f"GET /api/runs/{running_id}/acceptance (running): no figures yet", r.brief())
    api.expect_error(api.request(port, "GET", "/api/runs/999/acceptance"), 404)
    api.expect_error(api.request(port, "GET", "/api/runs/x1/acceptance"), 400)


def scenario(binary, tmp):
    db = os.path.join(tmp, "acc.db")
    r = subprocess.run([binary, "run", "--sim", "--gyros", "2", "--protocol", PROTOCOL, "--db", db,
                        "--parts", PARTS, "--part", "GX-200", "--json"], capture_output=True,
                       text=True, timeout=300)
    if r.returncode != 0:
        api.fatal(f"the acceptance run: exit {r.returncode}: {r.stderr[-800:]}")
    out = json.loads(r.stdout)
    run_id = out["run_id"]
    st = api.Station(binary, ["run", "--sim", "--speed", "200", "--gyros", "1", "--new",
                              "--http", "127.0.0.1:0", "--db", db], tmp, "ACC")
    try:
        port = st.wait_listening(30)
        if port is None:
            api.fatal(f"no listening line; exit {st.proc.poll()}; stderr {st.err_text()[-1500:]}")
        check_finished(port, db, run_id, out.get("acceptance"))
        check_running_and_bad(port, run_id + 1)
        st.proc.send_signal(signal.SIGTERM)
        api.check(st.wait_exit(30) == 0, "SIGTERM: exit 0 within 30 s")
    finally:
        st.kill()


def main():
    if len(sys.argv) != 2:
        print("usage: api_acceptance_test.py STATION_BINARY", file=sys.stderr)
        return 1
    binary = os.path.abspath(sys.argv[1])
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))
    t0 = time.time()
    tmp = tempfile.mkdtemp(prefix="api_acceptance_test.")
    try:
        scenario(binary, tmp)
    except api.Fatal:
        pass
    except Exception as e:  # a bug of the test itself, or an unexpected answer shape
        import traceback
        traceback.print_exc()
        api.FAILURES.append(f"unexpected {type(e).__name__}: {e}")
    print(f"{time.time() - t0:.1f} s")
    if api.FAILURES:
        print(f"\n{len(api.FAILURES)} FAILED (files kept in {tmp}):")
        for f in api.FAILURES:
            print(f"  - {f}")
        return 1
    shutil.rmtree(tmp, ignore_errors=True)
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
