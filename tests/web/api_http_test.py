#!/usr/bin/env python3
"""The station's HTTP API (schemas/api.md) with plain HTTP clients (standard library only).

Scenario A: `station run --sim --speed 200 --gyros 2 --http 127.0.0.1:0 --db TMP/a.db`:
  the port line and the token file (0600); the reads (/api/status, /api/live, /api/runs, one run,
  its bins and events); /metrics through `promtool check metrics` and specific series; the event
  stream (tick messages, increasing ids, ?after=SEQ with no gap, at most 4 streams: the 5th gets
  503, slots released on close); bad requests (401 + WWW-Authenticate, 403, 409, 400 for bad JSON,
  fields and ids, 404, 413 for a 1 MiB body with Content-Length, chunked or gzipped, 400 for
  Content-Length -1, 401 for a POST without Content-Length, path traversal, garbage request
  lines, a 20 KB header, bad percent-encoding; the daemon answering after each; each refusal
  counted in station_http_requests_total);
  no CORS header on any response and no CORS preflight; a second daemon on the same port (exit 2,
  one line naming the address); then the stop over the API (202, exit 0, final table, `stopped`).
Scenario D: a second run in the same database: the stopped run 1 is 409 for stop, runs newest
  first, its stored bins; SIGTERM ends the daemon with exit 0.
Scenario R: a completed short run with its fit; a daemon on the same database; POST
  /api/fits/{id}/release refused without or with a wrong token (401, 403), for bad bodies (400),
  unknown or malformed ids (404, 400); 201 with the token; 409 the second time; the release in
  /api/runs/{id} (slot "released") and in the database (releases row, 'release' event).
Scenario C: a new database, abort over the API once bins are complete: 202, exit 0, state
  `aborted`, no row in `fits` for the run.

Every check runs (a failed one does not stop the others unless what follows depends on it); each
failure is printed as `FAIL: what: expected ..., got ...`.

Usage: api_http_test.py STATION_BINARY       exit 0 pass, 1 fail
"""
import gzip
import http.client
import json
import os
import queue
import re
import shutil
import signal
import socket
import sqlite3
import stat
import subprocess
import sys
import tempfile
import threading
import time

LISTEN = re.compile(r"^http: listening on (http://127\.0\.0\.1:(\d+)/)\s*$")
HOST = "127.0.0.1"
FAILURES = []
WRONG_TOKEN = "0" * 64


class Fatal(Exception):
    """A failure the rest of the test cannot go on without."""


def ok(what):
    print(f"ok: {what}")


def check(cond, what, detail=""):
    if cond:
        ok(what)
    else:
        msg = f"{what}" + (f": {detail}" if detail else "")
        FAILURES.append(msg)
        print(f"FAIL: {msg}")
    return bool(cond)


def fatal(what):
    FAILURES.append(what)
    print(f"FAIL: {what}")
    raise Fatal(what)


def is_num(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


# ---- the daemon ---------------------------------------------------------------------------------


class Station:
    """`station ARGS` as a subprocess; stdout read to the end by a thread (lines kept), stderr to
    a file."""

    def __init__(self, binary, args, cwd, name):
        self.name = name
        self.stderr_path = os.path.join(cwd, f"{name}.stderr")
        self.stderr = open(self.stderr_path, "w")
        self.cmd = [binary] + args
        print(f"[{name}] starting: {' '.join(self.cmd)}")
        self.proc = subprocess.Popen(self.cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=self.stderr,
                                     stdin=subprocess.DEVNULL, text=True)
        self.lines = queue.Queue()
        self.stdout = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self.stdout.append(line)
            self.lines.put(line)
        self.lines.put(None)

    def out_text(self):
        return "".join(self.stdout)

    def err_text(self):
        self.stderr.flush()
        with open(self.stderr_path) as f:
            return f.read()

    def wait_listening(self, timeout_s=30):
        """The port of the `http: listening on` line; None if the process exited first or no
        such line came in time (the caller decides how bad that is)."""
        deadline = time.time() + timeout_s
        while time.time() < deadline:
            try:
                line = self.lines.get(timeout=max(0.05, deadline - time.time()))
            except queue.Empty:
                break
            if line is None:
                return None
            m = LISTEN.match(line.rstrip("\n"))
            if m:
                return int(m.group(2))
        return None

    def wait_exit(self, timeout_s):
        try:
            rc = self.proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            return None
        self.reader.join(timeout=5)
        return rc

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                pass
        self.stderr.close()


# ---- HTTP ---------------------------------------------------------------------------------------


class Resp:
    def __init__(self, what, status, headers, body):
        self.what = what
        self.status = status
        self.headers = headers  # [(name, value)]
        self.body = body

    def header(self, name):
        for k, v in self.headers:
            if k.lower() == name.lower():
                return v
        return None

    def json(self):
        try:
            return json.loads(self.body.decode("utf-8"))
        except (ValueError, UnicodeDecodeError):
            return None

    def brief(self):
        return f"{self.status} {self.body[:240]!r}"


CORS_SEEN = []  # requests answered with an Access-Control-* header


def note_cors(resp):
    cors = [(k, v) for k, v in resp.headers if k.lower().startswith("access-control-")]
    if cors:
        CORS_SEEN.append(f"{resp.what} -> {cors}")


def request(port, method, path, body=None, headers=None, timeout=10):
    what = f"{method} {path}"
    c = http.client.HTTPConnection(HOST, port, timeout=timeout)
    try:
        c.request(method, path, body=body, headers=headers or {})
        r = c.getresponse()
        data = r.read()
        resp = Resp(what, r.status, r.getheaders(), data)
    except (OSError, http.client.HTTPException) as e:
        resp = Resp(what, None, [], f"<no response: {e!r}>".encode())
    finally:
        c.close()
    note_cors(resp)
    return resp


def auth(token):
    return {"Authorization": f"Bearer {token}"}


def get_json(port, path):
    r = request(port, "GET", path)
    return r, (r.json() if r.status == 200 else None)


def expect(resp, status, what=None):
    return check(resp.status == status, what or resp.what,
                 f"expected {status}, got {resp.brief()}")


def expect_error(resp, status, what=None):
    """The status and the contract's error body: a JSON object {"error": "one line"}."""
    what = what or resp.what
    if not expect(resp, status, f"{what} -> {status}"):
        return False
    j = resp.json()
    ctype = resp.header("Content-Type") or ""
    return check(ctype.startswith("application/json") and isinstance(j, dict)
                 and isinstance(j.get("error"), str) and j["error"] and "\n" not in j["error"],
                 f"{what}: error body {{\"error\": one line}}",
                 f"got Content-Type {ctype!r}, body {resp.body[:200]!r}")


def raw_exchange(port, data, timeout=8, chunks=()):
    """Sends raw bytes and reads one response (by its Content-Length). Returns (status or None,
    header text, body, note)."""
    s = socket.create_connection((HOST, port), timeout=timeout)
    note = ""
    buf = b""
    try:
        try:
            s.sendall(data)
            for c in chunks:
                s.sendall(c)
        except OSError as e:
            note = f"send: {e!r}; "
        try:
            while b"\r\n\r\n" not in buf:
                d = s.recv(65536)
                if not d:
                    break
                buf += d
            head, _, body = buf.partition(b"\r\n\r\n")
            m = re.search(rb"(?im)^content-length:\s*(\d+)\s*$", head)
            if m:
                n = int(m.group(1))
                while len(body) < n:
                    d = s.recv(65536)
                    if not d:
                        break
                    body += d
        except OSError as e:
            note += f"recv: {e!r}"
            head, _, body = buf.partition(b"\r\n\r\n")
    finally:
        s.close()
    m = re.match(rb"HTTP/1\.[01] (\d{3})", head)
    status = int(m.group(1)) if m else None
    text = head.decode("latin-1")
    if re.search(r"(?im)^access-control-", text):
        CORS_SEEN.append(f"raw {data[:40]!r} -> {text!r}")
    return status, text, body, note


def still_up(port, after):
    r = request(port, "GET", "/api/status")
    return check(r.status == 200 and isinstance(r.json(), dict),
                 f"daemon still answers GET /api/status after {after}", r.brief())


def wait_for(pred, timeout_s, step_s=0.25):
    deadline = time.time() + timeout_s
    last = None
    while time.time() < deadline:
        last = pred()
        if last:
            return last
        time.sleep(step_s)
    return last


# ---- the event stream ---------------------------------------------------------------------------


def parse_sse(text):
    """Complete messages of an SSE text: [{"id", "event", "data", "lines"}], comments dropped."""
    msgs = []
    blocks = text.split("\n\n")
    for block in blocks[:-1]:  # the last one may be incomplete
        m = {"id": None, "event": None, "data": [], "lines": block.split("\n")}
        for line in m["lines"]:
            if line.startswith(":") or not line:
                continue
            k, _, v = line.partition(":")
            v = v[1:] if v.startswith(" ") else v
            if k == "data":
                m["data"].append(v)
            elif k in ("id", "event"):
                m[k] = v
        if m["id"] is None and m["event"] is None and not m["data"]:
            continue
        msgs.append(m)
    return msgs


def read_stream(port, seconds, path="/api/events/stream"):
    """Opens the stream and reads for `seconds`: (response status, content type, text)."""
    c = http.client.HTTPConnection(HOST, port, timeout=10)
    try:
        c.request("GET", path, headers={"Accept": "text/event-stream"})
        sock = c.sock  # the response keeps it: the connection drops it (Connection: close)
        r = c.getresponse()
        resp = Resp(f"GET {path}", r.status, r.getheaders(), b"")
        note_cors(resp)
        if r.status != 200:
            resp.body = r.read()
            return resp, ""
        sock.settimeout(1.0)
        data = b""
        deadline = time.time() + seconds
        while time.time() < deadline:
            try:
                d = r.read1(65536)
            except socket.timeout:
                continue
            except (OSError, http.client.HTTPException) as e:
                data += f"\n<read error {e!r}>".encode()
                break
            if not d:
                break
            data += d
        return resp, data.decode("utf-8", "replace")
    finally:
        c.close()


def open_raw_stream(port):
    """A stream held open on a raw socket: (socket, status)."""
    s = socket.create_connection((HOST, port), timeout=5)
    s.sendall(b"GET /api/events/stream HTTP/1.1\r\nHost: 127.0.0.1\r\n"
              b"Accept: text/event-stream\r\n\r\n")
    buf = b""
    try:
        while b"\r\n\r\n" not in buf:
            d = s.recv(4096)
            if not d:
                break
            buf += d
    except OSError:
        pass
    m = re.match(rb"HTTP/1\.[01] (\d{3})", buf)
    return s, (int(m.group(1)) if m else None), buf


# ---- /metrics -----------------------------------------------------------------------------------


def parse_metrics(text):
    """{'name{labels}': value} of the sample lines."""
    out = {}
    for line in text.splitlines():
        if not line or line.startswith("#"):
            continue
        m = re.match(r"^([a-zA-Z_:][a-zA-Z0-9_:]*(?:\{[^}]*\})?)\s+(\S+)", line)
        if m:
            try:
                out[m.group(1)] = float(m.group(2))
            except ValueError:
                out[m.group(1)] = m.group(2)
    return out


def check_metrics(port, run_id):
    r = request(port, "GET", "/metrics")
    expect(r, 200, "GET /metrics -> 200")
    ctype = r.header("Content-Type") or ""
    check(ctype.startswith("text/plain") and "version=0.0.4" in ctype,
          "GET /metrics: Content-Type text/plain; version=0.0.4", f"got {ctype!r}")
    text = r.body.decode("utf-8", "replace")
    if not check(text.strip() != "", "GET /metrics: body not empty"):
        return
    promtool = shutil.which("promtool")
    if promtool is None:
        print("SKIP: promtool not installed (Debian: prometheus); /metrics not linted")
    else:
        p = subprocess.run([promtool, "check", "metrics"], input=text, capture_output=True,
                           text=True, timeout=30)
        check(p.returncode == 0, "promtool check metrics: exit 0",
              f"exit {p.returncode}: {(p.stdout + p.stderr).strip()[:800]}")
    m = parse_metrics(text)
    buckets = [k for k in m if k.startswith("station_tick_duration_seconds_bucket{")]
    check(buckets and 'station_tick_duration_seconds_bucket{le="+Inf"}' in m,
          "metrics: station_tick_duration_seconds_bucket (with le=\"+Inf\")",
          f"buckets {buckets}")
    for name in ["station_tick_duration_seconds_count", "station_tick_duration_seconds_sum"]:
        check(name in m, f"metrics: {name}")
    check(is_num(m.get("station_ticks_total")) and m["station_ticks_total"] > 0,
          "metrics: station_ticks_total > 0", f"got {m.get('station_ticks_total')}")
    running = 'station_run_state{state="running"}'
    check(m.get(running) == 1, f"metrics: {running} 1", f"got {m.get(running)}")
    for st in ["idle", "hold", "fault"]:
        key = f'station_run_state{{state="{st}"}}'
        check(m.get(key) == 0, f"metrics: {key} 0", f"got {m.get(key)}")
    check(is_num(m.get("station_samples_stored_total")) and m["station_samples_stored_total"] > 0,
          "metrics: station_samples_stored_total > 0",
          f"got {m.get('station_samples_stored_total')}")
    http_codes = {k: v for k, v in m.items() if k.startswith("station_http_requests_total{")}
    check(is_num(http_codes.get('station_http_requests_total{code="200"}'))
          and http_codes['station_http_requests_total{code="200"}'] >= 1,
          'metrics: station_http_requests_total{code="200"} >= 1', f"got {http_codes}")
    check(m.get("station_run_id") == run_id, f"metrics: station_run_id {run_id}",
          f"got {m.get('station_run_id')}")
    for name in ["station_missed_ticks_total", "station_safe_hold", "station_chamber_air_celsius",
                 "station_chamber_setpoint_celsius", "station_table_rate_degrees_per_second",
                 "station_event_stream_clients"]:
        check(name in m, f"metrics: {name} present")
    check(m.get("station_safe_hold") == 0, "metrics: station_safe_hold 0",
          f"got {m.get('station_safe_hold')}")
    # Per gyro (issue 23): every series of a slot carries its serial and CAN node, and the bias
    # is the rate minus the slot's Earth rate (a simulated gyro's bias is far below a degree/h
    # of Earth rate, so rate - bias is the Earth rate along the axis, 0..15.04107 deg/h).
    rates = {k: v for k, v in m.items() if k.startswith("station_gyro_rate_degrees_per_hour{")}
    check(rates and all('serial="' in k and 'node="' in k for k in rates),
          "metrics: station_gyro_rate_degrees_per_hour per serial and node", f"got {rates}")
    for k, rate in rates.items():
        bias = m.get(k.replace("station_gyro_rate_", "station_gyro_bias_"))
        check(is_num(bias) and -0.01 <= rate - bias <= 15.05,
              f"metrics: {k}: rate - bias is the slot's Earth rate", f"rate {rate} bias {bias}")
        for fam in ["station_gyro_temperature_celsius", "station_gyro_gradient_celsius",
                    "station_gyro_latch_lost_total"]:
            labels = k[k.index("{"):]
            check(fam + labels in m, f"metrics: {fam}{labels} present")
    routes = {k: v for k, v in m.items() if k.startswith("station_http_route_requests_total{")}
    check(any('route="/api/status"' in k for k in routes),
          'metrics: station_http_route_requests_total{route="/api/status",...}', f"got {routes}")
    check(all(re.search(r'route="(/[^"]*|other)"', k) and "{id}" in k or "{id}" not in k
              for k in routes) and not any(re.search(r'route="[^"]*/\d', k) for k in routes),
          "metrics: routes carry {id}, never a number", f"got {list(routes)}")


def metric(port, key):
    r = request(port, "GET", "/metrics")
    if r.status != 200:
        return None
    return parse_metrics(r.body.decode("utf-8", "replace")).get(key)


# ---- scenario A: reads --------------------------------------------------------------------------


def check_reads(port, run_id_hint=None):
    # The port line comes before the first tick: wait for a status with the run and its slots.
    def ready():
        r, j = get_json(port, "/api/status")
        return (r, j) if j and j.get("run") and len(j.get("slots") or []) == 2 else None

    got = wait_for(ready, 10)
    r, st = got if got else get_json(port, "/api/status")
    expect(r, 200, "GET /api/status -> 200")
    check((r.header("Content-Type") or "").startswith("application/json"),
          "GET /api/status: Content-Type application/json", f"got {r.header('Content-Type')!r}")
    if not isinstance(st, dict):
        fatal(f"GET /api/status: expected a JSON object, got {r.brief()}")
    check(st.get("state") == "running", "status.state == running", f"got {st.get('state')!r}")
    check(st.get("station") == "simulated-rig" and st.get("sim") is True
          and st.get("speed") == 200.0, "status: station simulated-rig, sim true, speed 200",
          f"got {st.get('station')!r} {st.get('sim')!r} {st.get('speed')!r}")
    check(st.get("http") == f"http://127.0.0.1:{port}/", "status.http is the listening URL",
          f"got {st.get('http')!r}")
    run = st.get("run")
    if not isinstance(run, dict) or not isinstance(run.get("id"), int) or run["id"] <= 0:
        fatal(f"status.run.id: expected a positive integer, got run {run!r}")
    run_id = run["id"]
    ok(f"status.run.id = {run_id}")
    check(run.get("protocol") == "paper", "status.run.protocol == paper",
          f"got {run.get('protocol')!r}")
    steps = run.get("steps")
    check(isinstance(steps, list) and steps
          and all(isinstance(s, dict) and isinstance(s.get("label"), str)
                  and isinstance(s.get("kind"), str) for s in steps),
          "status.run.steps: non-empty list of {label, kind}", f"got {steps!r}")
    check(is_num(run.get("t_s")) and isinstance(run.get("step_index"), int)
          and isinstance(run.get("step_label"), str) and isinstance(run.get("recording"), bool),
          "status.run: t_s, step_index, step_label, recording typed", f"got {run!r}")
    ch = st.get("chamber")
    check(isinstance(ch, dict) and is_num(ch.get("air_c")), "status.chamber.air_c is a number",
          f"got chamber {ch!r}")
    check(isinstance(ch, dict) and {"air_c", "setpoint_c", "mode", "alarm"} <= set(ch),
          "status.chamber has air_c, setpoint_c, mode, alarm", f"got {ch!r}")
    tb = st.get("table")
    check(isinstance(tb, dict) and {"angle_deg", "rate_dps", "locked", "mode"} <= set(tb),
          "status.table has angle_deg, rate_dps, locked, mode", f"got {tb!r}")
    slots = st.get("slots")
    check(isinstance(slots, list) and len(slots) == 2, "status.slots has 2 entries",
          f"got {slots!r}")
    if isinstance(slots, list):
        check(all({"serial", "rate_dph", "bias_dph", "temp_c", "grad_c"} <= set(s)
                  for s in slots), "status.slots[*] has serial, rate_dph, bias_dph, temp_c, grad_c",
              f"got {slots!r}")
    sf = st.get("safety")
    check(isinstance(sf, dict)
          and {"safe_hold", "door_closed", "estop_pressed", "table_interlock_open"} <= set(sf),
          "status.safety has safe_hold, door_closed, estop_pressed, table_interlock_open",
          f"got {sf!r}")
    check(isinstance(st.get("ticks"), int) and st["ticks"] > 0, "status.ticks > 0",
          f"got {st.get('ticks')!r}")
    check(is_num(st.get("last_tick_ms")), "status.last_tick_ms is a number",
          f"got {st.get('last_tick_ms')!r}")
    check(st.get("last_run_id") == run_id, "status.last_run_id == run.id",
          f"got {st.get('last_run_id')!r}")

    r, lv = get_json(port, "/api/live")
    expect(r, 200, "GET /api/live -> 200")
    lv = lv if isinstance(lv, dict) else {}
    check({"status", "trend", "bins", "events", "seq"} <= set(lv),
          "/api/live has status, trend, bins, events, seq", f"got keys {sorted(lv)}")
    trend = lv.get("trend")
    check(isinstance(trend, list) and trend and len(trend) <= 2000
          and all(isinstance(p, list) and len(p) == 3 and is_num(p[0]) for p in trend),
          "/api/live.trend: 1..2000 points [t_s, air_c, setpoint_c]", f"got {str(trend)[:200]}")
    check(isinstance(lv.get("bins"), dict), "/api/live.bins is an object",
          f"got {lv.get('bins')!r}")
    ev = lv.get("events")
    check(isinstance(ev, list) and 0 < len(ev) <= 50
          and all({"id", "run_id", "t_s", "severity", "source", "kind", "message"} <= set(e)
                  and e["severity"] in ("info", "warn", "error") for e in ev),
          "/api/live.events: 1..50 EVENTs", f"got {str(ev)[:300]}")
    check(isinstance(lv.get("seq"), int) and lv["seq"] > 0, "/api/live.seq is a positive integer",
          f"got {lv.get('seq')!r}")
    check(isinstance(lv.get("status"), dict) and lv["status"].get("state") == "running",
          "/api/live.status.state == running")

    r, runs = get_json(port, "/api/runs")
    expect(r, 200, "GET /api/runs -> 200")
    mine = [x for x in runs if isinstance(x, dict) and x.get("id") == run_id] \
        if isinstance(runs, list) else []
    check(len(mine) == 1 and mine[0].get("state") == "running"
          and mine[0].get("protocol") == "paper",
          f"/api/runs lists run {run_id} (running, paper)", f"got {r.brief()}")
    r, one = get_json(port, "/api/runs?limit=1")
    check(r.status == 200 and isinstance(one, list) and len(one) == 1,
          "GET /api/runs?limit=1 -> 1 run", r.brief())

    r, rj = get_json(port, f"/api/runs/{run_id}")
    expect(r, 200, f"GET /api/runs/{run_id} -> 200")
    rj = rj if isinstance(rj, dict) else {}
    check(rj.get("id") == run_id and rj.get("state") == "running", "run record: id and state",
          f"got {r.brief()}")
    rs = rj.get("slots")
    check(isinstance(rs, list) and len(rs) == 2
          and all({"slot", "serial", "earth_rate_dph", "fit"} <= set(s) for s in rs),
          f"/api/runs/{run_id}.slots: 2 slots with serial, earth_rate_dph, fit", f"got {rs!r}")

    r, bj = get_json(port, f"/api/runs/{run_id}/bins")
    expect(r, 200, f"GET /api/runs/{run_id}/bins -> 200")
    check(isinstance(bj, dict) and bj.get("provisional") is True
          and isinstance(bj.get("serials"), dict),
          "bins while running: provisional true, serials object", f"got {r.brief()}")

    r, ej = get_json(port, f"/api/runs/{run_id}/events?since=0")
    expect(r, 200, f"GET /api/runs/{run_id}/events?since=0 -> 200")
    ej = ej if isinstance(ej, dict) else {}
    evs = ej.get("events")
    ids = [e.get("id") for e in evs] if isinstance(evs, list) else []
    check(isinstance(evs, list) and evs and all(isinstance(i, int) for i in ids)
          and all(a < b for a, b in zip(ids, ids[1:])),
          "events?since=0: non-empty, ids increasing", f"got ids {ids}")
    check(isinstance(evs, list)
          and all(e.get("run_id") == run_id and e.get("severity") in ("info", "warn", "error")
                  and {"t_s", "source", "kind", "message"} <= set(e) for e in evs),
          "events?since=0: EVENT fields, run_id of the run", f"got {str(evs)[:300]}")
    kinds = [e.get("kind") for e in evs] if isinstance(evs, list) else []
    check("run_start" in kinds, "events include run_start", f"kinds {kinds}")
    nxt = ej.get("next")
    check(isinstance(nxt, int) and ids and nxt == ids[-1], "events.next == the last id",
          f"next {nxt!r}, ids {ids}")
    if isinstance(nxt, int):
        r, e2 = get_json(port, f"/api/runs/{run_id}/events?since={nxt}")
        e2 = e2 if isinstance(e2, dict) else {}
        ids2 = [e.get("id") for e in e2.get("events") or []]
        check(r.status == 200 and isinstance(e2.get("events"), list)
              and all(isinstance(i, int) and i > nxt for i in ids2)
              and isinstance(e2.get("next"), int) and e2["next"] >= nxt,
              f"events?since={nxt}: none or newer, next >= {nxt}", f"got {r.brief()}")
    return run_id


# ---- scenario A: the event stream ---------------------------------------------------------------


def check_stream_messages(msgs, what, consecutive_from=None):
    ids = []
    bad = []
    ticks = []
    for m in msgs:
        try:
            ids.append(int(m["id"]))
        except (TypeError, ValueError):
            bad.append(f"id {m['id']!r}")
            continue
        if m["event"] is None or len(m["data"]) != 1:
            bad.append(f"message {m['lines']!r}: expected one event: and one data: line")
            continue
        try:
            data = json.loads(m["data"][0])
        except ValueError:
            bad.append(f"data not JSON: {m['data'][0][:200]!r}")
            continue
        if m["event"] == "tick":
            ticks.append(data)
    check(not bad, f"{what}: every message has id, event and one JSON data line", "; ".join(bad))
    check(ids and all(a < b for a, b in zip(ids, ids[1:])), f"{what}: ids increasing",
          f"ids {ids[:40]}")
    if consecutive_from is not None and ids:
        check(ids[0] == consecutive_from and all(b == a + 1 for a, b in zip(ids, ids[1:])),
              f"{what}: ids {consecutive_from}, {consecutive_from + 1}, ... with no gap",
              f"ids {ids[:40]}")
    return ids, ticks


def check_stream(port):
    # One stream, ~3 s.
    t0 = time.time()
    resp, text = read_stream(port, 3.0)
    elapsed = time.time() - t0
    expect(resp, 200, "GET /api/events/stream -> 200")
    ctype = resp.header("Content-Type") or ""
    check(ctype.startswith("text/event-stream"), "stream Content-Type text/event-stream",
          f"got {ctype!r}")
    msgs = parse_sse(text)
    ids, ticks = check_stream_messages(msgs, "stream")
    check(len(ticks) >= 1, "stream: at least one `event: tick` in ~3 s",
          f"{len(msgs)} messages, text {text[:300]!r}")
    keys = {"t_s", "state", "step_index", "step_label", "recording", "safe_hold", "air_c",
            "setpoint_c", "slots"}
    check(ticks and all(isinstance(t, dict) and keys <= set(t) and t["state"] == "running"
                        and isinstance(t["slots"], list) and len(t["slots"]) == 2
                        and all({"serial", "bias_dph", "temp_c", "grad_c"} <= set(s)
                                for s in t["slots"]) for t in ticks),
          "stream tick data: t_s, state running, step, recording, safe_hold, air/setpoint, "
          "2 slots with serial, bias_dph, temp_c, grad_c", f"first tick {ticks[:1]!r}")
    t_s = [t.get("t_s") for t in ticks if isinstance(t, dict)]
    check(all(is_num(a) and is_num(b) and a < b for a, b in zip(t_s, t_s[1:])),
          "stream ticks: t_s increasing", f"t_s {t_s[:20]}")
    limit = int(10 * elapsed) + 2
    check(len(ticks) <= limit, f"stream: at most 10 tick messages per wall second "
          f"(<= {limit} in {elapsed:.1f} s)", f"got {len(ticks)}")

    # ?after=SEQ of /api/live: the stream goes on from the snapshot with no gap.
    r, lv = get_json(port, "/api/live")
    seq = lv.get("seq") if isinstance(lv, dict) else None
    if isinstance(seq, int):
        time.sleep(0.5)  # messages published between the snapshot and the stream's open
        resp, text = read_stream(port, 1.0, f"/api/events/stream?after={seq}")
        expect(resp, 200, f"GET /api/events/stream?after={seq} -> 200")
        check_stream_messages(parse_sse(text), f"stream ?after={seq}", consecutive_from=seq + 1)
    else:
        check(False, "/api/live.seq for ?after", r.brief())
    r = request(port, "GET", "/api/events/stream?after=abc")
    expect_error(r, 400, "GET /api/events/stream?after=abc")

    # At most 4 streams at once: the 5th is refused with 503; closing frees the slots. The
    # streams read above hold their slots until the server's next write to them fails.
    def zero_clients():
        return metric(port, "station_event_stream_clients") == 0

    t = time.time()
    check(wait_for(zero_clients, 5, 0.05), "metrics: station_event_stream_clients 0 within 5 s "
          "of closing the streams", f"got {metric(port, 'station_event_stream_clients')}")
    print(f"info: stream slots released {time.time() - t:.2f} s after the client closed")
    held = []
    try:
        for i in range(4):
            s, status, head = open_raw_stream(port)
            held.append(s)
            check(status == 200, f"concurrent stream {i + 1} of 4 -> 200", f"got {head[:200]!r}")
        c = metric(port, "station_event_stream_clients")
        check(c == 4, "metrics: station_event_stream_clients 4 with 4 streams open", f"got {c}")
        r = request(port, "GET", "/api/events/stream")
        expect_error(r, 503, "5th concurrent GET /api/events/stream")
    finally:
        for s in held:
            s.close()

    def stream_again():
        s, status, _ = open_raw_stream(port)
        s.close()
        return status == 200

    check(wait_for(stream_again, 5), "a stream is accepted again within 5 s of closing the 4")
    check(wait_for(zero_clients, 5), "metrics: station_event_stream_clients back to 0 in 5 s",
          f"got {metric(port, 'station_event_stream_clients')}")


# ---- scenario A: bad requests -------------------------------------------------------------------


def check_bad_requests(port, token, run_id):
    # A POST with no body and no Content-Length (`curl -X POST URL`): valid HTTP/1.1 (an empty
    # body); the contract says 401 without a token. Run beside the rest: a server that waits for
    # a body holds it for its read timeout.
    nocl = {}

    def post_without_length():
        t = time.time()
        nocl["r"] = raw_exchange(port, f"POST /api/runs/{run_id}/stop HTTP/1.1\r\n"
                                       f"Host: 127.0.0.1\r\nConnection: close\r\n\r\n".encode(),
                                 timeout=15)
        nocl["s"] = time.time() - t

    th = threading.Thread(target=post_without_length)
    th.start()

    # Tokens.
    r = request(port, "POST", f"/api/runs/{run_id}/stop")
    if expect_error(r, 401, f"POST /api/runs/{run_id}/stop without Authorization"):
        check((r.header("WWW-Authenticate") or "").startswith("Bearer"),
              "401 carries WWW-Authenticate: Bearer", f"got {r.header('WWW-Authenticate')!r}")
    r = request(port, "POST", f"/api/runs/{run_id}/stop", headers=auth(WRONG_TOKEN))
    expect_error(r, 403, f"POST /api/runs/{run_id}/stop with a wrong token")
    r = request(port, "POST", f"/api/runs/{run_id}/abort", headers=auth("short"))
    expect_error(r, 403, f"POST /api/runs/{run_id}/abort with a wrong (short) token")
    r = request(port, "POST", f"/api/runs/{run_id}/stop",
                headers={"Authorization": f"Basic {token}"})
    expect_error(r, 403, f"POST /api/runs/{run_id}/stop with 'Basic TOKEN'")
    r = request(port, "POST", "/api/runs", body='{"protocol": "paper"}',
                headers={"Content-Type": "application/json"})
    expect_error(r, 401, "POST /api/runs without Authorization")
    still_up(port, "refused tokens")
    r, st = get_json(port, "/api/status")
    check(isinstance(st, dict) and st.get("state") == "running",
          "the run goes on after refused stops", f"got {r.brief()}")

    # POST /api/runs with the token.
    js = {"Content-Type": "application/json", **auth(token)}
    r = request(port, "POST", "/api/runs", body=json.dumps({"protocol": "paper",
                                                            "operator": "api-test"}), headers=js)
    expect_error(r, 409, "POST /api/runs while `station run` runs its one run")
    for body, what in [('{"protocol": "paper"', "malformed JSON"),
                       ("", "empty body"),
                       ('["paper"]', "a JSON array"),
                       ('"paper"', "a JSON string"),
                       ('{"operator": "ann"}', "protocol missing"),
                       ('{"protocol": 5, "operator": "ann"}', "protocol not a string"),
                       ('{"protocol": null}', "protocol null"),
                       ('{"protocol": "paper", "operator": 7}', "operator not a string"),
                       # Issue 34 points 10-11: the one text rule (station/common/text_rule.hpp).
                       ('{"protocol": "paper", "operator": "ann\\nEve"}', "operator with a newline"),
                       ('{"protocol": "paper", "operator": "ann\\u202e"}', "operator with U+202E"),
                       # Issue 34 point 11: a key the route does not know (a typo) is refused.
                       ('{"protocol": "paper", "operater": "ann"}', "an unknown key")]:
        r = request(port, "POST", "/api/runs", body=body, headers=js)
        expect_error(r, 400, f"POST /api/runs with {what}")
    r = request(port, "POST", "/api/runs", body='{"protocol": "paper", "operator": "ann\\u202e"}',
                headers=js)
    check(r.status == 400 and "field 'operator': U+202E at character 4" in ((r.json() or {}).get("error") or ""),
          "POST /api/runs: the refusal names the field, the character and its position", r.brief())

    r = request(port, "POST", "/api/runs", body='{"protocol": "paper", "operater": "ann"}',
                headers=js)
    check(r.status == 400 and "field 'operater': unknown" in ((r.json() or {}).get("error") or ""),
          "POST /api/runs: an unknown key is 400 naming it", r.brief())
    r = request(port, "POST", f"/api/runs/{run_id}/stop", body='{"force": true}', headers=js)
    check(r.status == 400 and "field 'force': unknown" in ((r.json() or {}).get("error") or ""),
          "POST /api/runs/{id}/stop with a field: 400 naming it (a stop takes none)", r.brief())

    # Ids: one canonical decimal form (issue 34 point 11: 01 read as 1).
    for path, status in [(f"/api/runs/0{run_id}", 400), (f"/api/runs/+{run_id}", 400),
                         (f"/api/runs/{run_id}.0", 400), (f"/api/runs/%20{run_id}", 400),
                         (f"/api/runs/0{run_id}/bins", 400),
                         (f"/api/runs/{run_id}/events?since=00", 400),
                         ("/api/runs?limit=010", 400),
                         ("/api/runs/999999", 404), ("/api/runs/999999/bins", 404),
                         ("/api/runs/999999/events", 404),
                         ("/api/runs/abc", 400), ("/api/runs/0", 400), ("/api/runs/-1", 400),
                         ("/api/runs/1.5", 400), ("/api/runs/%201", 400),
                         ("/api/runs/99999999999999999999999", 400),
                         ("/api/runs/abc/bins", 400), ("/api/runs/0/events", 400),
                         (f"/api/runs/{run_id}/events?since=abc", 400),
                         (f"/api/runs/{run_id}/events?since=-1", 400),
                         ("/api/runs?limit=0", 400), ("/api/runs?limit=x", 400),
                         ("/api/nothing", 404)]:
        expect_error(request(port, "GET", path), status)
    for path, status in [("/api/runs/999999/stop", 404), ("/api/runs/999999/abort", 404),
                         ("/api/runs/abc/stop", 400), ("/api/runs/0/abort", 400),
                         ("/api/runs/99999999999999999999999/stop", 400)]:
        expect_error(request(port, "POST", path, headers=auth(token)), status, f"POST {path}")

    # Body limit: 64 KiB. A 1 MiB body with its Content-Length: 413 (the server may answer before
    # reading it: the exchange reads the answer whatever the send did).
    big = b'{"protocol": "' + b"a" * (1 << 20) + b'"}'
    status, head, body, note = raw_exchange(
        port, (f"POST /api/runs HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer {token}\r\n"
               f"Content-Type: application/json\r\nContent-Length: {len(big)}\r\n"
               f"Connection: close\r\n\r\n").encode(), chunks=[big])
    check(status == 413, "POST /api/runs with a 1 MiB body (Content-Length) -> 413",
          f"got {status} {head[:120]!r} {body[:200]!r} {note}")
    check(status != 413 or (b'"error"' in body), "413 has an {\"error\"} body", f"{body[:200]!r}")
    still_up(port, "a 1 MiB body")
    # 1 MiB as a chunked body, a valid request padded (a 409 means it reached the handler): the
    # limit holds for any framing.
    padded = json.dumps({"protocol": "paper", "operator": "x", "pad": "a" * (1 << 20)}).encode()
    chunks = [b"%x\r\n" % len(padded[i:i + 65536]) + padded[i:i + 65536] + b"\r\n"
              for i in range(0, len(padded), 65536)] + [b"0\r\n\r\n"]
    status, head, body, note = raw_exchange(
        port, (f"POST /api/runs HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer {token}\r\n"
               f"Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n"
               f"Connection: close\r\n\r\n").encode(), chunks=chunks)
    check(status == 411, "POST /api/runs with a 1 MiB chunked body -> 411 (a POST needs a "
          "Content-Length, checked before any body is read)",
          f"got {status} {body[:200]!r} {note}")
    still_up(port, "a 1 MiB chunked body")
    # The same 1 MiB gzipped (~1 KB on the wire): 413 (the body is 1 MiB) or 415 (no encodings).
    gz = gzip.compress(padded)
    status, head, body, note = raw_exchange(
        port, (f"POST /api/runs HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer {token}\r\n"
               f"Content-Type: application/json\r\nContent-Encoding: gzip\r\n"
               f"Content-Length: {len(gz)}\r\nConnection: close\r\n\r\n").encode() + gz)
    check(status in (413, 415), f"POST /api/runs with 1 MiB gzipped to {len(gz)} bytes "
          f"(Content-Encoding: gzip) -> 413 or 415", f"got {status} {body[:200]!r} {note}")
    still_up(port, "a gzipped 1 MiB body")
    r = request(port, "POST", "/api/runs", body=b'{"protocol": "paper", "operator": "x"}'
                + b" " * 60000, headers=js)
    expect_error(r, 409, "POST /api/runs with a 60 KB body (under the limit) reaches the handler")

    # Path traversal and the static files.
    for path in ["/static/../../etc/passwd", "/static/..%2F..%2Fetc%2Fpasswd",
                 "/static/%2e%2e/%2e%2e/etc/passwd", "/../../etc/passwd",
                 "/static/%2e%2e%2f%2e%2e%2fetc%2fpasswd", "/static/....//....//etc/passwd",
                 "/static/dygraphs/../../../etc/passwd",
                 "/static/dygraphs/..%2F..%2F..%2Fetc%2Fpasswd",
                 "/static/dygraphs/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
                 "/static/dygraphs/dygraph.min.js/../../../../etc/passwd",
                 "/static/%2Fetc%2Fpasswd", "//etc/passwd", "/static//etc/passwd"]:
        r = request(port, "GET", path)
        check(r.status is not None and r.status != 200 and b"root:" not in r.body,
              f"GET {path} -> not 200, no 'root:'", r.brief())
    r = request(port, "GET", "/static/dygraphs/dygraph.min.js")
    check(r.status == 200 and len(r.body) > 10000
          and "javascript" in (r.header("Content-Type") or ""),
          "GET /static/dygraphs/dygraph.min.js -> 200, javascript, the libjs-dygraphs file",
          f"got {r.status} {r.header('Content-Type')!r} {len(r.body)} bytes")
    dy = "/usr/share/javascript/dygraphs/dygraph.min.js"
    if os.path.exists(dy) and r.status == 200:
        with open(dy, "rb") as f:
            check(f.read() == r.body, f"dygraph.min.js is {dy} byte for byte")
    r = request(port, "GET", "/static/dygraphs/dygraph.js")
    check(r.status == 404, "GET /static/dygraphs/dygraph.js (not in the served list) -> 404",
          r.brief())
    r = request(port, "GET", "/")
    check(r.status == 200 and (r.header("Content-Type") or "").startswith("text/html"),
          "GET / -> 200 text/html", f"got {r.status} {r.header('Content-Type')!r}")

    # Garbage on the wire: each gets a 4xx (or the connection closed), and the daemon answers.
    for data, what in [
            (b"GARBAGE\r\n\r\n", "a garbage request line"),
            (b"\x00\xff\xfe\r\n\r\n", "binary bytes"),
            (b"GET /api/status HTTP/1.1\r\nHost: x\r\nX-Big: " + b"a" * 20000 + b"\r\n\r\n",
             "a 20 KB header line"),
            (b"GET /api/status HTTP/1.1\r\nHost: x\r\nX-Big: " + b"a" * 9000 + b"\r\n\r\n",
             "a 9 KB header (over the 8 KiB field limit)"),
            (b"GET /api/status?" + b"a" * 20000 + b" HTTP/1.1\r\nHost: x\r\n\r\n",
             "a 20 KB request target"),
            (b"GET /api/runs/%zz HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
             "invalid percent-encoding in a run id"),
            (b"GET /static/%ZZ%2 HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
             "invalid percent-encoding in a static name"),
            (b"GET /static/index.html%00.js HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
             "a %00 in a static name"),
            (b"GET /api/status HTTP/9.9\r\nHost: x\r\nConnection: close\r\n\r\n",
             "HTTP/9.9"),

            (b"POST /api/runs HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\n"
             b"Connection: close\r\n\r\nzz\r\n", "a bad chunk size")]:
        try:
            status, head, body, note = raw_exchange(port, data, timeout=10)
        except OSError as e:
            status, head, body, note = None, "", b"", repr(e)
        check(status is None or 400 <= status < 500,
              f"{what}: a 4xx answer or a closed connection",
              f"got {status} {head[:100]!r} {body[:100]!r} {note}")
        still_up(port, what)
    # A malformed Content-Length is refused at once, not waited for as a body over the limit.
    t = time.time()
    status, head, body, note = raw_exchange(
        port, (f"POST /api/runs HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer {token}\r\n"
               f"Content-Length: -1\r\nConnection: close\r\n\r\n").encode(), timeout=10)
    # An invalid Content-Length is a framing error: 400 (RFC 9112 6.3, item 5), before the token.
    check(status == 400 and time.time() - t < 2, "POST with Content-Length: -1 -> 400 at once",
          f"got {status} after {time.time() - t:.1f} s: {body[:120]!r} {note}")
    still_up(port, "Content-Length -1")

    # CORS: no header on any answer (checked on every one), no preflight.
    r = request(port, "OPTIONS", "/api/runs",
                headers={"Origin": "http://evil.example", "Access-Control-Request-Method": "POST",
                         "Access-Control-Request-Headers": "authorization, content-type"})
    allow = [(k, v) for k, v in r.headers if k.lower().startswith("access-control-allow")]
    check(r.status is not None and not (200 <= r.status < 300) and not allow,
          "OPTIONS preflight /api/runs -> not 2xx, no Access-Control-Allow-*",
          f"got {r.status} {allow}")
    r = request(port, "GET", "/api/status", headers={"Origin": "http://evil.example"})
    check(r.status == 200 and r.header("Access-Control-Allow-Origin") is None,
          "GET /api/status with Origin: no Access-Control-Allow-Origin")

    th.join(timeout=20)
    status, head, body, note = nocl.get("r", (None, "", b"", "thread did not finish"))
    check(status == 401 and "www-authenticate: bearer" in head.lower(),
          f"POST /api/runs/{run_id}/stop without Content-Length nor Authorization "
          f"(`curl -X POST`) -> 401 with WWW-Authenticate",
          f"got {status} after {nocl.get('s', -1):.1f} s: {body[:200]!r} {note}")
    still_up(port, "a POST without Content-Length")
    # With the token, the README's `curl -X POST -H "Authorization: Bearer $T" URL` (no body, no
    # Content-Length) is a valid empty body: answered as any POST, not 411. Real curl, on a run
    # that does not exist: 404 names it.
    out = subprocess.run(["curl", "-sS", "-o", "/dev/null", "-w", "%{http_code}", "-X", "POST",
                          "-H", f"Authorization: Bearer {token}",
                          f"http://127.0.0.1:{port}/api/runs/999999/stop"],
                         capture_output=True, text=True, timeout=20)
    check(out.stdout.strip() == "404",
          "curl -X POST with the token and no body on /api/runs/999999/stop -> 404 (not 411)",
          f"got {out.stdout!r} {out.stderr!r}")

    # Every refusal above was counted.
    r = request(port, "GET", "/metrics")
    m = parse_metrics(r.body.decode("utf-8", "replace"))
    for code in ["400", "401", "403", "404", "409", "413", "503"]:
        key = f'station_http_requests_total{{code="{code}"}}'
        check(is_num(m.get(key)) and m[key] >= 1, f"metrics: {key} >= 1", f"got {m.get(key)}")


# ---- scenario A: a second daemon on the same port -----------------------------------------------


def check_port_taken(binary, tmp, port):
    other = Station(binary, ["run", "--sim", "--speed", "200", "--gyros", "2",
                             "--http", f"127.0.0.1:{port}",
                             "--db", os.path.join(tmp, "b.db")], tmp, "second")
    try:
        # It must exit at once; one that printed its listening line has bound the taken port.
        deadline = time.time() + 15
        while time.time() < deadline and other.proc.poll() is None \
                and "listening" not in other.out_text():
            time.sleep(0.1)
        rc = other.wait_exit(0.5)
        if rc is None:
            check(False, f"a second daemon with --http 127.0.0.1:{port} (taken) exits 2",
                  f"it keeps running; stdout {other.out_text()[:300]!r} (it listens on the "
                  f"same port beside the first: requests go to either)")
            return
        err = other.err_text().strip()
        check(rc == 2, f"a second daemon with --http 127.0.0.1:{port} (taken) exits 2",
              f"exit {rc}; stderr {err[:400]!r}")
        lines = [x for x in err.splitlines() if x.strip()]
        check(len(lines) == 1 and f"127.0.0.1:{port}" in lines[0],
              "its error is one line naming the address", f"stderr {err[:400]!r}")
        check("listening" not in other.out_text(), "it printed no listening line",
              f"stdout {other.out_text()[:200]!r}")
    finally:
        other.kill()


# ---- scenarios ----------------------------------------------------------------------------------


def final_table(st, run_id, state):
    out = st.out_text()
    check(re.search(rf"(?m)^run {run_id} \({state}\)", out) is not None,
          f"stdout ends with 'run {run_id} ({state})'", f"stdout {out[-600:]!r}")
    check(re.search(r"(?m)^serial\s+B0", out) is not None and "SIM-0001" in out
          and "SIM-0002" in out, "stdout has the final table (serial header, both gyros)",
          f"stdout {out[-600:]!r}")


def db_state(db, run_id):
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    try:
        row = con.execute("SELECT state, ended_utc FROM runs WHERE id = ?", (run_id,)).fetchone()
        fits = con.execute("SELECT id, serial, runs_json FROM fits").fetchall()
        bins = con.execute("SELECT COUNT(*) FROM bins WHERE run_id = ?", (run_id,)).fetchone()[0]
    finally:
        con.close()
    mine = [f for f in fits if run_id in (json.loads(f[2]) if f[2] else [])]
    return row, mine, bins


def wait_complete_bins(port, n, timeout_s):
    """Until /api/live shows >= n complete live bins for each of the 2 serials."""
    def enough():
        _, lv = get_json(port, "/api/live")
        bins = lv.get("bins") if isinstance(lv, dict) else None
        if not isinstance(bins, dict) or len(bins) != 2:
            return None
        counts = [sum(1 for b in v if isinstance(b, dict) and b.get("complete")) for v in
                  bins.values()]
        return bins if min(counts) >= n else None

    return wait_for(enough, timeout_s, 0.5)


def scenario_a(binary, tmp):
    db = os.path.join(tmp, "a.db")
    st = Station(binary, ["run", "--sim", "--speed", "200", "--gyros", "2",
                          "--http", "127.0.0.1:0", "--db", db], tmp, "A")
    try:
        port = st.wait_listening(30)
        if port is None:
            fatal(f"[A] no 'http: listening on http://127.0.0.1:PORT/' line within 30 s; exit "
                  f"{st.proc.poll()}; stdout {st.out_text()[:400]!r}; stderr "
                  f"{st.err_text()[-1500:]}")
        ok(f"[A] listening on port {port}")
        tok_path = db + ".token"
        if not os.path.exists(tok_path):
            fatal(f"token file {tok_path} not created")
        mode = stat.S_IMODE(os.stat(tok_path).st_mode)
        check(mode == 0o600, f"token file {os.path.basename(tok_path)} mode 0600",
              f"got {mode:o}")
        with open(tok_path) as f:
            tok_text = f.read()
        token = tok_text.strip()
        check(len(tok_text.splitlines()) == 1 and len(token) >= 16 and " " not in token,
              "token file: one line of >= 16 characters", f"got {len(tok_text)} bytes")

        run_id = check_reads(port)
        check_metrics(port, run_id)
        check_stream(port)
        check_bad_requests(port, token, run_id)
        check_port_taken(binary, tmp, port)
        r, stj = get_json(port, "/api/status")
        check(isinstance(stj, dict) and stj.get("run", {}).get("id") == run_id
              and stj.get("state") == "running",
              f"[A] still runs run {run_id} after all that", r.brief())
        if st.proc.poll() is not None:
            fatal(f"[A] the daemon exited ({st.proc.returncode}) during the test; stderr "
                  f"{st.err_text()[-1500:]}")

        # Stored bins need a complete live bin first (recording starts ~1.1 h simulated in).
        bins = wait_complete_bins(port, 1, 45)
        check(bins, "[A] a complete live bin per serial within 45 s")
        if bins:
            r, bj = get_json(port, f"/api/runs/{run_id}/bins")
            ser = bj.get("serials") if isinstance(bj, dict) else None
            keys = {"t_mid_s", "temp_c", "grad_c", "bias_dph", "n", "complete"}
            check(isinstance(bj, dict) and bj.get("provisional") is True and isinstance(ser, dict)
                  and len(ser) == 2 and all(v and all(keys <= set(b) for b in v)
                                            for v in ser.values()),
                  "bins while recording: provisional, 2 serials of BINs {t_mid_s, temp_c, "
                  "grad_c, bias_dph, n, complete}", r.brief())

        # Stop with the token: 202, exit 0 in 60 s, the run `stopped`, the final table.
        r = request(port, "POST", f"/api/runs/{run_id}/stop", headers=auth(token))
        expect(r, 202, f"POST /api/runs/{run_id}/stop with the token -> 202")
        j = r.json()
        check(isinstance(j, dict) and isinstance(j.get("accepted"), str),
              "202 body {\"accepted\": text}", r.brief())
        rc = st.wait_exit(60)
        if rc is None:
            fatal(f"[A] the daemon did not exit within 60 s of the stop; stderr "
                  f"{st.err_text()[-1500:]}")
        check(rc == 0, "[A] exit 0 after the stop", f"exit {rc}; stderr {st.err_text()[-1500:]}")
        final_table(st, run_id, "stopped")
        row, fits, nbins = db_state(db, run_id)
        check(row is not None and row[0] == "stopped" and row[1],
              f"[A] database: run {run_id} state 'stopped', ended_utc set", f"got {row}")
        check(nbins > 0, f"[A] database: the stopped run's bins are stored", f"{nbins} bins")
        return db, run_id
    finally:
        st.kill()


def check_release(port, token, db, run_id):
    """POST /api/fits/{id}/release while another run runs: refusals, 201, 409 again, and the
    release in the run's JSON and the database."""
    with sqlite3.connect(f"file:{db}?mode=ro", uri=True) as c:
        fits = c.execute("SELECT id, serial FROM fits WHERE runs_json = ? ORDER BY id",
                         (f"[{run_id}]",)).fetchall()
    if not fits:
        FAILURES.append(f"[R] run {run_id} has no fit to release")
        return
    fit_id, serial = fits[0]
    path = f"/api/fits/{fit_id}/release"
    js = {"Content-Type": "application/json", **auth(token)}
    expect_error(request(port, "POST", path, body=b'{"by":"x"}'), 401, f"[R] POST {path} no token")
    expect_error(request(port, "POST", path, body=b'{"by":"x"}', headers=auth(WRONG_TOKEN)), 403,
                 f"[R] POST {path} wrong token")
    for body, what in [(b"{", "bad JSON"), (b'{"note":"n"}', "no 'by'"), (b'{"by":""}', "empty 'by'"),
                       (b'{"by":7}', "'by' not a string"), (b"[]", "not an object"),
                       (b'{"by":"Ann\\u202e"}', "U+202E in 'by'"),
                       (b'{"by":"Ann","note":"a\\u0000b"}', "NUL in 'note'"),
                       (b'{"by":"Ann","overide":"typo"}', "an unknown key")]:
        expect_error(request(port, "POST", path, body=body, headers=js), 400, f"[R] POST {path} {what}")
    for bad, status in [("/api/fits/999999/release", 404), ("/api/fits/abc/release", 400),
                        ("/api/fits/0/release", 400), (f"/api/fits/0{fit_id}/release", 400),
                        (f"/api/fits/+{fit_id}/release", 400), (f"/api/fits/{fit_id}.0/release", 400),
                        (f"/api/fits/%20{fit_id}/release", 400)]:
        expect_error(request(port, "POST", bad, body=b'{"by":"x"}', headers=js), status, f"[R] POST {bad}")
    r = request(port, "POST", path, body=json.dumps({"by": "api-test", "note": "from curl"}).encode(),
                headers=js)
    if expect(r, 201, f"[R] POST {path} with the token -> 201"):
        got = r.json() or {}
        check(got.get("fit_id") == fit_id and got.get("serial") == serial and got.get("by") == "api-test",
              f"[R] release reply names fit {fit_id} of {serial}", r.brief())
    expect_error(request(port, "POST", path, body=b'{"by":"again"}', headers=js), 409,
                 f"[R] POST {path} again: already the released calibration")
    r, run = get_json(port, f"/api/runs/{run_id}")
    rel = [s.get("released") for s in (run or {}).get("slots", []) if s.get("serial") == serial]
    check(rel and isinstance(rel[0], dict) and rel[0].get("fit_id") == fit_id
          and rel[0].get("by") == "api-test" and rel[0].get("note") == "from curl",
          f"[R] /api/runs/{run_id}: slot {serial} shows the release", f"got {rel!r}")
    with sqlite3.connect(f"file:{db}?mode=ro", uri=True) as c:
        rows = c.execute("SELECT fit_id, released_by FROM releases").fetchall()
        ev = c.execute("SELECT kind FROM events WHERE run_id = ? AND kind = 'release'",
                       (run_id,)).fetchall()
    check(rows == [(fit_id, "api-test")], "[R] one row in releases", f"got {rows}")
    check(len(ev) == 1, f"[R] one 'release' event on run {run_id}", f"got {ev}")
    still_up(port, "release requests")


def scenario_d(binary, tmp, db, stopped_id):
    """The same database again: a new run beside the stopped one."""
    st = Station(binary, ["run", "--sim", "--speed", "200", "--gyros", "2",
                          "--http", "127.0.0.1:0", "--db", db], tmp, "D")
    try:
        port = st.wait_listening(30)
        if port is None:
            fatal(f"[D] no listening line; exit {st.proc.poll()}; stderr {st.err_text()[-1500:]}")
        token = open(db + ".token").read().strip()
        got = wait_for(lambda: (get_json(port, "/api/status")[1] or {}).get("run"), 10)
        new_id = got.get("id") if isinstance(got, dict) else None
        check(new_id == stopped_id + 1, f"[D] a new run {stopped_id + 1} in the same database",
              f"got run {got!r}")
        r = request(port, "POST", f"/api/runs/{stopped_id}/stop", headers=auth(token))
        expect_error(r, 409, f"[D] POST /api/runs/{stopped_id}/stop (exists, not running)")
        r = request(port, "POST", f"/api/runs/{stopped_id}/abort", headers=auth(token))
        expect_error(r, 409, f"[D] POST /api/runs/{stopped_id}/abort (exists, not running)")
        r, runs = get_json(port, "/api/runs")
        ids = [x.get("id") for x in runs] if isinstance(runs, list) else []
        check(ids == [new_id, stopped_id], "[D] /api/runs newest first", f"got ids {ids}")
        r, old = get_json(port, f"/api/runs/{stopped_id}")
        check(isinstance(old, dict) and old.get("state") == "stopped" and old.get("ended_utc"),
              f"[D] /api/runs/{stopped_id}: state stopped, ended_utc set", r.brief())
        r, bj = get_json(port, f"/api/runs/{stopped_id}/bins")
        ser = bj.get("serials") if isinstance(bj, dict) else None
        keys = {"t_start_s", "temp_c", "grad_c", "bias_dph", "n", "complete"}
        check(isinstance(bj, dict) and bj.get("provisional") is False and isinstance(ser, dict)
              and len(ser) == 2,
              f"[D] /api/runs/{stopped_id}/bins: stored (provisional false), 2 serials",
              r.brief())
        if isinstance(ser, dict) and ser:
            first = next(iter(ser.values()))
            check(first and all(keys <= set(b) for b in first),
                  f"[D] stored bins {{{', '.join(sorted(keys))}}} (api.md: t_start_s, not t_mid_s)",
                  f"got {first[:1]!r}")
        r, ev = get_json(port, f"/api/runs/{stopped_id}/events?since=0")
        kinds = [e.get("kind") for e in (ev or {}).get("events", [])]
        check(r.status == 200 and kinds, f"[D] events of the stopped run readable", r.brief())
        st.proc.send_signal(signal.SIGTERM)
        rc = st.wait_exit(30)
        check(rc == 0, "[D] SIGTERM: exit 0 within 30 s", f"exit {rc}")
    finally:
        st.kill()


def scenario_r(binary, tmp):
    """A completed short run with its fit, then a daemon on the same database: the release over
    the API while that daemon runs."""
    db = os.path.join(tmp, "r.db")
    short = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "short_cycle.toml")
    r = subprocess.run([binary, "run", "--sim", "--gyros", "1", "--protocol", short, "--db", db,
                        "--json"], capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        fatal(f"[R] the short run: exit {r.returncode}: {r.stderr[-800:]}")
    run_id = json.loads(r.stdout)["run_id"]
    st = Station(binary, ["run", "--sim", "--speed", "200", "--gyros", "1", "--new",
                          "--http", "127.0.0.1:0", "--db", db], tmp, "R")
    try:
        port = st.wait_listening(30)
        if port is None:
            fatal(f"[R] no listening line; exit {st.proc.poll()}; stderr {st.err_text()[-1500:]}")
        token = open(db + ".token").read().strip()
        check_release(port, token, db, run_id)
        st.proc.send_signal(signal.SIGTERM)
        check(st.wait_exit(30) == 0, "[R] SIGTERM: exit 0 within 30 s")
    finally:
        st.kill()


def scenario_c(binary, tmp):
    db = os.path.join(tmp, "c.db")
    st = Station(binary, ["run", "--sim", "--speed", "1000", "--gyros", "2",
                          "--http", "127.0.0.1:0", "--db", db], tmp, "C")
    try:
        port = st.wait_listening(30)
        if port is None:
            fatal(f"[C] no listening line; exit {st.proc.poll()}; stderr {st.err_text()[-1500:]}")
        token = open(db + ".token").read().strip()
        got = wait_for(lambda: (get_json(port, "/api/status")[1] or {}).get("run"), 10)
        run_id = got.get("id") if isinstance(got, dict) else None
        if not isinstance(run_id, int):
            fatal(f"[C] no run in /api/status: {got!r}")
        # Enough complete bins that a stop would fit (>= 4 for 3 coefficients): the abort's "no
        # fit" then means something.
        bins = wait_complete_bins(port, 5, 40)
        check(bins, "[C] 5 complete live bins per serial within 40 s")
        r = request(port, "POST", f"/api/runs/{run_id}/abort", headers=auth(WRONG_TOKEN))
        expect_error(r, 403, f"[C] POST /api/runs/{run_id}/abort with a wrong token")
        r = request(port, "POST", f"/api/runs/{run_id}/abort", headers=auth(token))
        expect(r, 202, f"[C] POST /api/runs/{run_id}/abort with the token -> 202")
        rc = st.wait_exit(60)
        if rc is None:
            fatal(f"[C] the daemon did not exit within 60 s of the abort")
        check(rc == 0, "[C] exit 0 after the abort", f"exit {rc}; stderr {st.err_text()[-1500:]}")
        check(re.search(rf"(?m)^run {run_id} \(aborted\)", st.out_text()) is not None,
              f"[C] stdout says 'run {run_id} (aborted)'", f"stdout {st.out_text()[-600:]!r}")
        row, fits, nbins = db_state(db, run_id)
        check(row is not None and row[0] == "aborted", f"[C] database: run {run_id} 'aborted'",
              f"got {row}")
        check(not fits, f"[C] database: no row in fits for run {run_id}", f"got {fits}")
        print(f"info: [C] aborted run {run_id} has {nbins} stored bins")
    finally:
        st.kill()


def main():
    if len(sys.argv) != 2:
        print("usage: api_http_test.py STATION_BINARY", file=sys.stderr)
        return 1
    binary = os.path.abspath(sys.argv[1])
    if not os.access(binary, os.X_OK):
        print(f"FAIL: {binary}: not an executable", file=sys.stderr)
        return 1
    # ctest's timeout sends SIGTERM: unwind through the `finally`s that kill the daemons.
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))
    t0 = time.time()
    tmp = tempfile.mkdtemp(prefix="api_http_test.")
    try:
        db, run_id = scenario_a(binary, tmp)
        scenario_d(binary, tmp, db, run_id)
        scenario_c(binary, tmp)
        scenario_r(binary, tmp)
    except Fatal:
        pass
    except Exception as e:  # a bug of the test itself, or an unexpected answer shape
        import traceback
        traceback.print_exc()
        FAILURES.append(f"unexpected {type(e).__name__}: {e}")
    check(not CORS_SEEN, "no Access-Control-* header on any response", "; ".join(CORS_SEEN))
    print(f"{time.time() - t0:.1f} s")
    if FAILURES:
        print(f"\n{len(FAILURES)} FAILED (daemon files kept in {tmp}):")
        for f in FAILURES:
            print(f"  - {f}")
        return 1
    shutil.rmtree(tmp, ignore_errors=True)
    print("PASS")
    return 0


if __name__ == "__main__":
    rc = 1
    try:
        rc = main()
    finally:
        sys.stdout.flush()
    sys.exit(rc)
