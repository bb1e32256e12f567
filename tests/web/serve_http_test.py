#!/usr/bin/env python3
"""`station serve` as a service, through plain HTTP: a simrig process (wall clock, real Modbus TCP
and CAN over a unix socket) stands in for the rig.

  serve_http_test.py STATION SIMRIG

Checks: READY=1 and WATCHDOG=1 every second on NOTIFY_SOCKET (what systemd's Type=notify and
WatchdogSec see); idle state with the rig read and no run; a run started over the API (token), running;
a second start refused (409); stop over the API -> idle again with the run 'stopped'; a second
run started on the same service; SIGKILL mid-run, then a new serve resumes that same run at
start; SIGUSR1 (the upgrade hand-over) -> exit 75 with the run resumable, resumed by the next
serve; SIGUSR1 then SIGTERM -> the run stopped; abort; a start while the rig is faulted (simrig stopped) is refused with 409 naming the fault,
and the service keeps answering; SIGTERM -> exit 0. Exit 0 ok, 1 failure.
"""
import json
import os
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

FAILURES = []


def check(cond, what):
    if not cond:
        FAILURES.append(what)
        print("FAIL:", what, flush=True)
    return cond


def request(base, method, path, token=None, body=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(base + path, data=data, method=method)
    if token:
        req.add_header("Authorization", "Bearer " + token)
    if method == "POST" and data is None:
        req.add_header("Content-Length", "0")
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, json.loads(r.read() or b"null")
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"null")


def wait_for(pred, timeout_s, what):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        v = pred()
        if v:
            return v
        time.sleep(0.2)
    check(False, "timed out waiting for " + what)
    return None


def start_serve(station, work, log_name, env=None):
    err = open(os.path.join(work, log_name), "w")
    p = subprocess.Popen([station, "serve", "--config", "rig.toml", "--db", "s.db", "--http",
                          "127.0.0.1:0"], cwd=work, stdout=subprocess.PIPE, stderr=err, text=True,
                         env=env)
    line = p.stdout.readline()
    if not line.startswith("http: listening on "):
        p.kill()
        raise SystemExit("serve did not print its address: %r (see %s)" % (line, log_name))
    return p, line.split()[-1].rstrip("/")


def db_query(work, sql, *args):
    """One row of the service's database, read with its own connection."""
    db = sqlite3.connect(os.path.join(work, "s.db"))
    try:
        return db.execute(sql, args).fetchone()
    finally:
        db.close()


def run_state(work, run_id):
    return db_query(work, "SELECT state FROM runs WHERE id = ?", run_id)[0]


def samples_of(work, run_id):
    return db_query(work, "SELECT COUNT(*) FROM samples WHERE run_id = ?", run_id)[0]


def status(base):
    return request(base, "GET", "/api/status")[1]


def main():
    station, simrig = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    work = tempfile.mkdtemp(prefix="serve-test-")
    rig_cfg = open(os.path.join(work, "rig.toml"), "w")
    rig = subprocess.Popen([simrig, "--gyros", "2", "--control", os.path.join(work, "ctl"),
                            "--can-socket", os.path.join(work, "can.sock")],
                           stdout=rig_cfg, stderr=subprocess.DEVNULL, cwd=work)
    procs = [rig]
    try:
        wait_for(lambda: os.path.getsize(os.path.join(work, "rig.toml")) > 200, 10, "simrig")
        time.sleep(0.3)
        # What systemd would see (Type=notify, WatchdogSec): sd_notify datagrams on NOTIFY_SOCKET.
        notify = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        notify.bind(os.path.join(work, "notify"))
        notify.settimeout(0.2)
        env = dict(os.environ, NOTIFY_SOCKET=os.path.join(work, "notify"), WATCHDOG_USEC="10000000")
        serve, base = start_serve(station, work, "serve1.log", env)
        procs.append(serve)
        notes, end = [], time.monotonic() + 3.5
        while time.monotonic() < end:
            try:
                notes.append(notify.recv(4096).decode())
            except socket.timeout:
                pass
        check(notes and notes[0] == "READY=1", "READY=1 first: %s" % notes[:3])
        check(notes.count("WATCHDOG=1") >= 2, "WATCHDOG=1 every second while idle: %s" % notes)
        token_path = os.path.join(work, "s.db.token")
        check(os.stat(token_path).st_mode & 0o777 == 0o600, "token file is 0600")
        token = open(token_path).read().strip()

        st = wait_for(lambda: (lambda s: s if s["chamber"] else None)(status(base)), 10,
                      "the idle rig read")
        check(st["state"] == "idle" and st["run"] is None, "idle with no run: %s" % st["state"])
        check(abs(st["chamber"]["air_c"] - 25.0) < 5, "chamber air read while idle")

        code, body = request(base, "POST", "/api/runs", None, {"protocol": "paper"})
        check(code == 401, "start without a token: 401, got %d" % code)
        code, body = request(base, "POST", "/api/runs", token, {"protocol": "no_such"})
        check(code == 400 and "unknown" in body["error"], "unknown protocol: 400 %s" % body)
        code, body = request(base, "POST", "/api/runs", token,
                             {"protocol": "paper", "operator": "ann"})
        check(code == 202 and body.get("run_id", 0) > 0, "start: 202 with the run id, got %d %s"
              % (code, body))
        st = wait_for(lambda: (lambda s: s if s["state"] == "running" and s["run"] else None)(
            status(base)), 15, "the run to start")
        run1 = st["run"]["id"]
        check(st["run"]["operator"] == "ann" and st["run"]["protocol"] == "paper",
              "run carries protocol and operator")
        code, body = request(base, "POST", "/api/runs", token, {"protocol": "paper"})
        check(code == 409, "a second start while running: 409, got %d" % code)
        wait_for(lambda: status(base)["ticks"] >= 3, 10, "three ticks")

        code, _ = request(base, "POST", "/api/runs/%d/stop" % run1, token)
        check(code == 202, "stop: 202, got %d" % code)
        wait_for(lambda: status(base)["state"] == "idle", 15, "idle after stop")
        code, run = request(base, "GET", "/api/runs/%d" % run1)
        check(code == 200 and run["state"] == "stopped", "run 1 stopped: %s" % run.get("state"))

        # A second run on the same service, then the daemon killed mid-run.
        code, _ = request(base, "POST", "/api/runs", token, {"protocol": "paper"})
        check(code == 202, "second start: 202, got %d" % code)
        st = wait_for(lambda: (lambda s: s if s["run"] and s["run"]["id"] != run1 else None)(
            status(base)), 15, "the second run")
        run2 = st["run"]["id"] if st else -1
        wait_for(lambda: status(base)["ticks"] >= 3, 10, "ticks of run 2")
        serve.send_signal(signal.SIGKILL)
        serve.wait(10)
        state = run_state(work, run2)
        check(state == "running", "killed run left 'running': %s" % state)

        serve, base = start_serve(station, work, "serve2.log")
        procs.append(serve)
        st = wait_for(lambda: (lambda s: s if s["run"] else None)(status(base)), 15,
                      "the resumed run")
        check(st and st["run"]["id"] == run2, "the killed run resumes at start")
        code, ev = request(base, "GET", "/api/runs/%d/events?since=0" % run2)
        check(any(e["kind"] == "resume" for e in ev["events"]), "a resume event is stored")

        # SIGUSR1, the package upgrade's hand-over: exit 75 with the run left resumable, its
        # ticks committed; the next serve (systemd's restart) resumes it.
        wait_for(lambda: status(base)["ticks"] >= 3, 10, "ticks of the resumed run")
        serve.send_signal(signal.SIGUSR1)
        rc = serve.wait(15)
        check(rc == 75, "SIGUSR1: exit 75 (EX_TEMPFAIL, restart me), got %d" % rc)
        state = run_state(work, run2)
        check(state == "running", "run left 'running' by SIGUSR1: %s" % state)
        last = db_query(work, "SELECT kind FROM events WHERE run_id = ? ORDER BY id DESC LIMIT 1",
                        run2)[0]
        check(last == "detach", "a detach event is the run's last: %s" % last)
        n_before = samples_of(work, run2)
        serve, base = start_serve(station, work, "serve3.log")
        procs.append(serve)
        st = wait_for(lambda: (lambda s: s if s["run"] else None)(status(base)), 15,
                      "the run resumed after the hand-over")
        check(st and st["run"]["id"] == run2, "the handed-over run resumes")
        wait_for(lambda: status(base)["ticks"] >= 2, 10, "ticks after the hand-over")
        n_after = samples_of(work, run2)
        check(n_before > 0 and n_after > n_before,
              "samples kept and added across the hand-over: %d -> %d" % (n_before, n_after))
        # A stop right after a hand-over request wins: the run ends 'stopped', exit 0. Both are
        # made pending while the process is stopped, so both handlers run before its next line
        # (without that, under load the loop may have left for the hand-over before SIGTERM).
        serve.send_signal(signal.SIGSTOP)
        serve.send_signal(signal.SIGUSR1)
        serve.send_signal(signal.SIGTERM)
        serve.send_signal(signal.SIGCONT)
        rc = serve.wait(15)
        check(rc == 0, "SIGUSR1 then SIGTERM: exit 0, got %d" % rc)
        state = run_state(work, run2)
        check(state == "stopped", "SIGUSR1 then SIGTERM: run 2 stopped: %s" % state)

        serve, base = start_serve(station, work, "serve4.log")
        procs.append(serve)
        wait_for(lambda: status(base)["state"] == "idle", 15, "idle on a fourth serve")
        code, body = request(base, "POST", "/api/runs", token, {"protocol": "paper"})
        run3 = body.get("run_id", 0) if code == 202 else 0
        check(run3 > run2, "third run started: %d %s" % (code, body))
        wait_for(lambda: status(base)["ticks"] >= 2, 10, "ticks of run 3")
        code, _ = request(base, "POST", "/api/runs/%d/abort" % run3, token)
        check(code == 202, "abort: 202, got %d" % code)
        wait_for(lambda: status(base)["state"] in ("idle", "fault"), 15, "idle after abort")
        code, run = request(base, "GET", "/api/runs/%d" % run3)
        check(run["state"] == "aborted", "run 3 aborted: %s" % run["state"])

        # The rig goes away: the service reports a fault, refuses a start, keeps answering.
        rig.send_signal(signal.SIGTERM)
        rig.wait(10)
        st = wait_for(lambda: (lambda s: s if s["state"] == "fault" else None)(status(base)), 20,
                      "fault state with the rig gone")
        code, body = request(base, "POST", "/api/runs", token, {"protocol": "paper"})
        check(code == 409 and "not ready" in body.get("error", ""),
              "start on a faulted rig: 409, got %d %s" % (code, body))
        serve.send_signal(signal.SIGTERM)
        rc = serve.wait(15)
        check(rc == 0, "SIGTERM: exit 0, got %d" % rc)
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait()
    if FAILURES:
        print("%d failure(s); logs in %s" % (len(FAILURES), work))
        return 1
    print("serve: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
