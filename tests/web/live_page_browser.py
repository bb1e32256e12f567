#!/usr/bin/env python3
"""The live page in a real browser: `station run --sim --speed 300 --http 127.0.0.1:0`, then the
page it serves opened in headless Chromium (Selenium + chromedriver). Checks that the page shows
the run and follows it by itself (state, step, t, the chamber chart growing, the bias charts
filling from `bin` messages), that a stop with a wrong token is refused on the page and the run
goes on, that a stop with the right token ends the run (the page shows it and the station exits
0), that the console logged nothing SEVERE but the expected refusal, and keeps a screenshot.

Usage: live_page_browser.py STATION_BINARY ARTIFACT_DIR
Exit 0 pass, 1 fail, 77 skip (Chromium, chromedriver or python3-selenium absent).
"""
import json
import os
import queue
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

SKIP = 77
LISTEN = re.compile(r"^http: listening on (http://127\.0\.0\.1:(\d+)/)\s*$")
TOKEN_KEY = "station.token"  # live.js keeps the bearer token here (sessionStorage)


class Failure(Exception):
    pass


def skip(why):
    print(f"SKIP: {why}")
    sys.exit(SKIP)


def fail(why):
    raise Failure(why)


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
    for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1400,1700",
              "--disable-dev-shm-usage"]:
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(executable_path=driver), options=opts)


class Station:
    """`station run` as a subprocess; its stdout is read by a thread to the end (so a progress
    line can never fill the pipe and stall the daemon), stderr goes to a file."""

    def __init__(self, binary, tmp):
        self.db = os.path.join(tmp, "live.db")
        self.stderr_path = os.path.join(tmp, "station.stderr")
        self.stderr = open(self.stderr_path, "w")
        cmd = [binary, "run", "--sim", "--speed", "300", "--gyros", "2",
               "--http", "127.0.0.1:0", "--db", self.db]
        print("starting:", " ".join(cmd))
        self.proc = subprocess.Popen(cmd, cwd=tmp, stdout=subprocess.PIPE, stderr=self.stderr,
                                     stdin=subprocess.DEVNULL, text=True)
        self.lines = queue.Queue()
        self.stdout = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            self.stdout.append(line)
            self.lines.put(line)
        self.lines.put(None)

    def err_text(self):
        self.stderr.flush()
        with open(self.stderr_path) as f:
            return f.read().strip()[-4000:]

    def wait_listening(self, timeout_s=30):
        deadline = time.time() + timeout_s
        while time.time() < deadline:
            try:
                line = self.lines.get(timeout=max(0.05, deadline - time.time()))
            except queue.Empty:
                break
            if line is None:
                self.proc.wait(timeout=5)
                fail(f"station exited ({self.proc.returncode}) before listening; stderr:\n"
                     f"{self.err_text()}")
            m = LISTEN.match(line.rstrip("\n"))
            if m:
                return m.group(1)
        fail(f"no 'http: listening on http://127.0.0.1:PORT/' line on stdout within {timeout_s} s;"
             f" stdout so far: {''.join(self.stdout)[-2000:]!r}; stderr:\n{self.err_text()}")

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=10)
        self.stderr.close()


def get_json(url):
    with urllib.request.urlopen(url, timeout=5) as r:
        return json.loads(r.read().decode())


def wait_for(what, pred, timeout_s, step_s=0.2):
    deadline = time.time() + timeout_s
    last = None
    while time.time() < deadline:
        last = pred()
        if last:
            return last
        time.sleep(step_s)
    fail(f"{what}: not within {timeout_s} s")


class Console:
    """The browser console, drained at each phase; SEVERE entries fail unless `allowed` says
    they are the expected consequence of that phase."""

    def __init__(self, drv):
        self.drv = drv

    def check(self, phase, allowed=lambda e: False):
        entries = self.drv.get_log("browser")
        severe = [e for e in entries if e.get("level") == "SEVERE"]
        bad = [e for e in severe if not allowed(e)]
        for e in severe:
            if allowed(e):
                print(f"console ({phase}, expected): {e.get('message')}")
        if bad:
            fail(f"console errors during {phase}: {[e.get('message') for e in bad]}")


def text(drv, id_):
    return drv.execute_script(f"return document.getElementById('{id_}').textContent.trim();")


def points(drv, id_):
    v = drv.execute_script(f"return document.getElementById('{id_}').getAttribute('data-points');")
    return int(v or 0)


def current_step(drv):
    return drv.execute_script(
        "var c = document.querySelectorAll('#steps li.current');"
        "return c.length === 1 ? c[0].textContent.trim() : (c.length ? 'MANY' : '');")


def set_prompt(drv, answer):
    """window.prompt answers `answer` (headless Chromium would otherwise block on the dialog)."""
    drv.execute_script(
        "window.__prompts = []; var a = arguments[0];"
        "window.prompt = function (q) { window.__prompts.push(q); return a; };"
        "window.confirm = function () { return true; };", answer)


STEP_DETAIL = {
    # kind -> what its line must show: target and nominal duration (h:mm)
    "set_temperature": re.compile(r"→ (start temperature )?−?\d+\.\d °C at [\d.]+ °C/h, \d+:\d\d"
                                  r"|→ .*°C, as fast as the chamber goes"),
    "soak": re.compile(r"stable within ±[\d.]+ °C for \d+:\d\d"),
    "hold": re.compile(r"for \d+:\d\d"),
}


def check_steps(drv):
    """Each step shows what it does: a set_temperature step its target, rate and duration
    (never its kind twice), a to_start step the start temperature once known."""
    steps = drv.execute_script(
        "return Array.prototype.map.call(document.querySelectorAll('#steps li'), function (li) {"
        " return {kind: li.getAttribute('data-kind'), text: li.textContent.trim()}; });")
    for s in steps:
        if s["kind"] in s["text"]:
            fail(f"step {s['text']!r} shows its kind's code name, not what it does")
        want = STEP_DETAIL.get(s["kind"])
        if want and not want.search(s["text"]):
            fail(f"step {s['text']!r} does not show its target and duration ({want.pattern})")
    if not any("start temperature" in s["text"] and "°C" in s["text"] for s in steps):
        fail(f"no step shows the start temperature it returns to: {steps}")
    print("steps: " + "; ".join(s["text"] for s in steps))


def check_target(drv, target):
    """While a ramp moves the setpoint, the step's target shows beside it."""
    def seen():
        t = text(drv, "target-c")
        sp = text(drv, "setpoint-c")
        return (t, sp) if t == f"{target:.1f} °C" and sp != f"{target:.2f} °C" and sp != "— °C" \
            else None
    t, sp = wait_for(f"#target-c {target:.1f} °C beside a moving setpoint", seen, 30, 0.1)
    print(f"setpoint {sp}, target {t}")


def check_clock(drv):
    """The slot values' time is the clock's: both from the tick they came with."""
    for _ in range(20):
        clock, at = drv.execute_script(
            "return [document.getElementById('t-s').textContent,"
            " document.getElementById('slots-at').textContent];")
        if clock != at:
            fail(f"slot values labelled at {at!r} while the clock reads {clock!r}")
        time.sleep(0.2)
    print(f"slot values at the clock's time ({clock})")


AXES_JS = """
var out = [];
['chart-temp', 'chart-bias-time', 'chart-bias-temp'].forEach(function (id) {
  var el = document.getElementById(id);
  ['x', 'y'].forEach(function (a) {
    var labs = Array.prototype.map.call(
      el.querySelectorAll('.dygraph-axis-label-' + a), function (l) {
        var r = document.createRange(); r.selectNodeContents(l);
        var b = r.getBoundingClientRect();
        return {text: l.textContent, l: b.left, r: b.right, t: b.top, b: b.bottom,
                cut: l.scrollWidth > l.clientWidth + 1};
      });
    out.push({chart: id, axis: a, labels: labs});
  });
});
return out;
"""


def check_axes(drv):
    """Every chart's tick labels: none repeated, cut or over another."""
    for ax in drv.execute_script(AXES_JS):
        texts = [lab["text"] for lab in ax["labels"]]
        name = f"#{ax['chart']} {ax['axis']}"
        if len(set(texts)) != len(texts):
            fail(f"{name}: repeated tick labels {texts}")
        if any(lab["cut"] for lab in ax["labels"]):
            fail(f"{name}: cut tick labels {texts}")
        labs = ax["labels"]
        for i, a in enumerate(labs):
            for b in labs[i + 1:]:
                if min(a["r"], b["r"]) - max(a["l"], b["l"]) > 0.5 and \
                        min(a["b"], b["b"]) - max(a["t"], b["t"]) > 0.5:
                    fail(f"{name}: {a['text']!r} overlaps {b['text']!r}")
        print(f"{name}: {' '.join(texts)}")


def run_checks(drv, st, url, token, artifacts):
    console = Console(drv)
    drv.get(url)
    wait_for("page load", lambda: drv.execute_script("return document.readyState") == "complete",
             20)
    wait_for("#state shows running", lambda: text(drv, "state") == "running", 20)
    run_id = text(drv, "run-id")
    print(f"page: state running, run {run_id}, step '{text(drv, 'step-label')}',"
          f" t {text(drv, 't-s')}")
    if not run_id.isdigit():
        fail(f"#run-id is {run_id!r}")
    for id_ in ["steps", "chart-temp", "chart-bias-time", "chart-bias-temp", "events", "banner",
                "btn-start", "btn-stop", "btn-abort", "message"]:
        if not drv.execute_script(f"return !!document.getElementById('{id_}');"):
            fail(f"no element #{id_}")
    n_steps = drv.execute_script("return document.querySelectorAll('#steps li').length;")
    if n_steps < 2:
        fail(f"#steps lists {n_steps} steps")
    if drv.execute_script("return !document.getElementById('banner').hidden;"):
        fail(f"a banner is shown while running normally: {text(drv, 'banner')!r}")

    check_steps(drv)
    check_clock(drv)

    # The page follows the run by itself (no reload): t changes, the trend grows.
    t0, p0 = text(drv, "t-s"), points(drv, "chart-temp")
    wait_for(f"#t-s changing from {t0}", lambda: text(drv, "t-s") != t0, 10)
    wait_for(f"chart-temp data-points growing from {p0}",
             lambda: points(drv, "chart-temp") > p0, 10)
    print(f"t {t0} -> {text(drv, 't-s')}, chart-temp {p0} -> {points(drv, 'chart-temp')} points")

    # Recording starts at -40 C (after the cool-down), then 600 s bins arrive as `bin` messages.
    step0 = text(drv, "step-label")
    t_start = time.time()
    wait_for("bias charts getting points (bin messages)",
             lambda: points(drv, "chart-bias-time") >= 1 and points(drv, "chart-bias-temp") >= 1,
             90, 0.5)
    print(f"bias charts filling after {time.time() - t_start:.1f} s:"
          f" {points(drv, 'chart-bias-time')} / {points(drv, 'chart-bias-temp')} points")
    # The bias charts' captions name the width the daemon bins at (/api/status bin_s), not a
    # width written into the page.
    bin_s = get_json(url + "api/status").get("bin_s")
    captions = drv.execute_script(
        "return Array.prototype.map.call(document.querySelectorAll('figcaption'),"
        " function (c) { return c.textContent; }).filter(function (t) {"
        " return t.indexOf('Bias') === 0; });")
    want = f"in {bin_s:g} s bins"
    if not isinstance(bin_s, (int, float)) or len(captions) != 2 or \
            any(want not in c for c in captions):
        fail(f"bias captions {captions} do not say '{want}' (/api/status bin_s {bin_s!r})")
    print(f"captions name the bin width: {captions}")
    wait_for(f"#step-label changing from {step0!r}", lambda: text(drv, "step-label") != step0, 10)
    label, cur = text(drv, "step-label"), current_step(drv)
    if not cur or cur == "MANY" or label not in cur:
        fail(f"#steps li.current is {cur!r}, #step-label {label!r}")
    print(f"step '{step0}' -> '{label}' (li.current '{cur}')")
    # Heating to +70 C at 10 C/h: the setpoint moves, the target stays.
    check_target(drv, 70.0)
    check_clock(drv)
    # A few more bins for the screenshot (2 s wall each at speed 300).
    n = points(drv, "chart-bias-time")
    try:
        wait_for("more bins", lambda: points(drv, "chart-bias-time") >= n + 8, 15, 0.5)
    except Failure:
        pass
    for id_ in ["chart-temp", "chart-bias-time", "chart-bias-temp"]:
        if not drv.execute_script(f"return !!document.querySelector('#{id_} canvas');"):
            fail(f"#{id_} has no canvas (dygraphs did not draw)")
        if points(drv, id_) > 2000:
            fail(f"#{id_} holds {points(drv, id_)} points (more than 2000)")
    shot = os.path.join(artifacts, "live_page.png")
    drv.save_screenshot(shot)
    check_axes(drv)
    print(f"screenshot {shot} (chart-temp {points(drv, 'chart-temp')},"
          f" bias/time {points(drv, 'chart-bias-time')},"
          f" bias/T {points(drv, 'chart-bias-temp')} points)")
    console.check("the run")
    # The page follows the stream: /api/live is read on load (and again only on a run's start
    # or end or a reopened stream), never polled.
    reads = drv.execute_script(
        "return performance.getEntriesByType('resource').filter(function (e) {"
        " return e.name.indexOf('/api/') >= 0 && e.name.indexOf('/api/events/stream') < 0; })"
        ".map(function (e) { return e.name; });")
    print(f"API reads during the run: {reads}")
    if len(reads) > 3:
        fail(f"the page polls the API: {len(reads)} reads in the run: {reads}")

    # Stop with a wrong token: refused on the page, the run goes on.
    drv.execute_script(f"sessionStorage.setItem('{TOKEN_KEY}', 'wrong-token');")
    set_prompt(drv, "wrong-token")
    drv.find_element("id", "btn-stop").click()
    msg = wait_for("#message showing the refusal",
                   lambda: (lambda m: m if re.search(r"refused|40[13]", m) else None)(
                       text(drv, "message")), 10)
    print(f"wrong token: #message {msg!r}")
    if drv.execute_script(f"return sessionStorage.getItem('{TOKEN_KEY}');") is not None:
        fail("the refused token was kept in sessionStorage")
    if drv.execute_script("return window.__prompts.length;") > 1:
        fail("the page prompted for a token more than once after one refusal")
    time.sleep(2)
    if text(drv, "state") != "running":
        fail(f"#state is {text(drv, 'state')!r} after a refused stop")
    api = get_json(url + "api/status")
    if api.get("state") != "running" or st.proc.poll() is not None:
        fail(f"after a refused stop: /api/status state {api.get('state')!r},"
             f" process {st.proc.poll()}")
    stop_url = re.compile(r"/api/runs/\d+/stop")
    console.check("the refused stop", lambda e: bool(stop_url.search(e.get("message", "")))
                  and re.search(r"\b403\b", e.get("message", "")) is not None)

    # Stop with the right token (prompted, as sessionStorage was cleared).
    set_prompt(drv, token)
    drv.find_element("id", "btn-stop").click()
    wait_for("#state leaving running", lambda: text(drv, "state") not in ("running", ""), 30)
    ended = wait_for("a run end on the page (#run-end)",
                     lambda: (lambda t: t if "ended" in t else None)(text(drv, "run-end")), 30)
    print(f"right token: #state {text(drv, 'state')!r}, #run-end {ended!r},"
          f" #message {text(drv, 'message')!r}")
    how = drv.execute_script("return document.getElementById('run-end').dataset.runState;")
    if how != "stopped":
        fail(f"the run ended {how!r}, expected 'stopped' (the `run` message's state)")
    if drv.execute_script("return window.__prompts.length;") != 1:
        fail(f"expected one token prompt, got {drv.execute_script('return window.__prompts;')}")
    try:
        rc = st.proc.wait(timeout=60)
    except subprocess.TimeoutExpired:
        fail("the station did not exit within 60 s of its run's end")
    if rc != 0:
        fail(f"station exit {rc}; stderr:\n{st.err_text()}")
    print("station exited 0")
    # Once the daemon is gone the page's EventSource (and a last /api/live read) find nothing
    # listening: connection errors to the station's own URLs are expected then, nothing else.
    console.check("the stop and the daemon's exit",
                  lambda e: url in e.get("message", "") and "net::ERR_" in e.get("message", ""))


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        sys.exit(2)
    binary, artifacts = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    os.makedirs(artifacts, exist_ok=True)
    drv = browser()
    tmp = tempfile.mkdtemp(prefix="live-page-")
    st = None
    try:
        st = Station(binary, tmp)
        url = st.wait_listening(30)
        print(f"station at {url}")
        token_path = st.db + ".token"
        wait_for(f"token file {token_path}", lambda: os.path.exists(token_path), 10)
        mode = stat.S_IMODE(os.stat(token_path).st_mode)
        if mode != 0o600:
            fail(f"{token_path} has mode {oct(mode)}, expected 0o600")
        with open(token_path) as f:
            token = f.read().strip()
        if not token or "\n" in token:
            fail(f"{token_path} is not one line")
        run_checks(drv, st, url, token, artifacts)
    except Failure as e:
        print(f"FAIL: {e}")
        if st is not None:
            err = st.err_text() if st.proc.poll() is not None else ""
            if err:
                print(f"station stderr (tail):\n{err}")
        sys.exit(1)
    finally:
        drv.quit()
        if st is not None:
            st.kill()
        shutil.rmtree(tmp, ignore_errors=True)
    print("PASS")


if __name__ == "__main__":
    main()
