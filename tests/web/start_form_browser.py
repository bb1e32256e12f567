#!/usr/bin/env python3
"""The live page's start form (issue 35) in headless Chromium: `station serve` on simrig with a
configuration that names no serials (the rig, not the gyros). The form shows a serial field per
slot; a barcode scanner types each serial then Enter: Enter moves to the next slot's serial and
after the last to the Start button, never sending half a batch; Start with a slot left empty
says which slot and sends nothing; a full batch starts the run with the scanned serials (the
run's slots in the database). Keeps a screenshot (docs/live_start_form.png when asked).

Usage: start_form_browser.py STATION SIMRIG ARTIFACT_DIR
Exit 0 pass, 1 fail, 77 skip (Chromium, chromedriver or python3-selenium absent).
"""
import os
import re
import shutil
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

SKIP = 77
LISTEN = re.compile(r"http: listening on (http://127\.0\.0\.1:\d+/)")


def skip(why):
    print(f"SKIP: {why}")
    sys.exit(SKIP)


def browser():
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        skip("python3-selenium is not importable (Debian: python3-selenium)")
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if not chromium or not driver:
        skip("chromium and chromedriver are needed (Debian: chromium chromium-driver)")
    opts = webdriver.ChromeOptions()
    opts.binary_location = chromium
    for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1400,1100",
              "--disable-dev-shm-usage"]:
        opts.add_argument(a)
    return webdriver.Chrome(service=Service(executable_path=driver), options=opts)


def wait_for(what, pred, timeout_s=20):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        v = pred()
        if v:
            return v
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


def runs(db):
    if not os.path.exists(db):
        return []
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    try:
        return con.execute("SELECT r.id, s.slot, s.serial, s.gyro_source FROM runs r "
                           "JOIN run_slots s ON s.run_id = r.id ORDER BY r.id, s.slot").fetchall()
    except sqlite3.Error:
        return []
    finally:
        con.close()


def rig_config(simrig, tmp):
    sim = subprocess.Popen([simrig, "--gyros", "2", "--seed", "5", "--can-socket",
                            os.path.join(tmp, "can.sock")], stdout=subprocess.PIPE,
                           stderr=subprocess.DEVNULL, text=True)
    text = ""
    while True:  # the configuration ends with the last slot's axis line
        line = sim.stdout.readline()
        if not line:
            sim.kill()
            raise AssertionError("simrig printed no configuration")
        text += line
        if "SIM-0002" in text and line.startswith("axis"):
            break
    lines = [l for l in text.splitlines() if not l.startswith("serial = ")]
    cfg = os.path.join(tmp, "station.toml")
    with open(cfg, "w") as f:
        f.write("\n".join(lines) + f'\n\n[http]\nprotocol_dir = "{tmp}"\n')
    with open(os.path.join(tmp, "scan.toml"), "w") as f:
        f.write('name = "scan"\n[[step]]\ntype = "record_start"\n[[step]]\ntype = "hold"\n'
                'duration_s = 600\n')
    return sim, cfg


def main():
    station, simrig, artifacts = sys.argv[1:4]
    os.makedirs(artifacts, exist_ok=True)
    try:
        from selenium.webdriver.common.by import By
        from selenium.webdriver.common.keys import Keys
    except ImportError:
        skip("python3-selenium is not importable (Debian: python3-selenium)")
    tmp = tempfile.mkdtemp(prefix="start-form-")
    sim, serve, drv = None, None, None
    try:
        sim, cfg = rig_config(simrig, tmp)
        db = os.path.join(tmp, "station.db")
        serve = subprocess.Popen([station, "serve", "--config", cfg, "--db", db, "--http",
                                  "127.0.0.1:0"], stdout=subprocess.PIPE,
                                 stderr=subprocess.DEVNULL, text=True)
        url = None
        for _ in range(20):  # the listening line (stdout)
            m = LISTEN.search(serve.stdout.readline())
            if m:
                url = m.group(1)
                break
        assert url, "serve printed no listening line"
        token = open(db + ".token").read().strip()
        drv = browser()
        drv.get(url)
        drv.execute_script("sessionStorage.setItem('station.token', arguments[0])", token)
        start = drv.find_element(By.ID, "btn-start")
        wait_for("the Start button", lambda: start.is_enabled())
        start.click()
        form = drv.find_element(By.ID, "start-form")
        wait_for("the start form", form.is_displayed)
        serials = drv.find_elements(By.CSS_SELECTOR, "#start-slots input.start-serial")
        assert len(serials) == 2, f"{len(serials)} serial fields for 2 slots"
        active = lambda: drv.switch_to.active_element.get_attribute("id")
        assert active() == "start-serial-1", f"focus on {active()}, not slot 1's serial"
        # A scanner: the text, then Enter. Nothing is sent until the batch is complete.
        drv.switch_to.active_element.send_keys("SCAN-0001" + Keys.ENTER)
        assert active() == "start-serial-2", f"Enter moved to {active()}, not slot 2's serial"
        time.sleep(1.0)
        assert runs(db) == [], f"half a batch started a run: {runs(db)}"
        # Start with slot 2 empty: the form says so and sends nothing.
        drv.find_element(By.ID, "start-go").click()
        err = drv.find_element(By.ID, "start-error").text
        assert "slot 2" in err, f"an empty slot 2 gave '{err}'"
        assert runs(db) == [], "a start with an empty slot was sent"
        drv.find_element(By.ID, "start-serial-2").click()
        drv.switch_to.active_element.send_keys("SCAN-0002" + Keys.ENTER)
        err = drv.find_element(By.ID, "start-error").text
        assert err == "", f"the error stayed after the serial was typed: '{err}'"
        assert active() == "start-go", f"Enter after the last serial moved to {active()}"
        time.sleep(1.0)
        assert runs(db) == [], "Enter after the last serial sent the start by itself"
        drv.save_screenshot(os.path.join(artifacts, "live_start_form.png"))
        drv.switch_to.active_element.send_keys(Keys.ENTER)  # the operator confirms
        got = wait_for("the run", lambda: runs(db), 20)
        assert [r[2:] for r in got] == [("SCAN-0001", "start"), ("SCAN-0002", "start")], got
        print("PASS: start form: scanned serials, Enter to the next slot, no half batch")
        return 0
    except AssertionError as e:
        print(f"FAIL: {e}")
        return 1
    finally:
        if drv:
            drv.quit()
        if serve:
            serve.send_signal(signal.SIGTERM)
            try:
                serve.wait(20)
            except subprocess.TimeoutExpired:
                serve.kill()
        if sim:
            sim.terminate()
            sim.wait(10)


if __name__ == "__main__":
    sys.exit(main())
