#!/usr/bin/env python3
"""`station serve` when its database cannot be written (issue 19 item 4): a simrig process stands
in for the rig; the serve process's file size limit (RLIMIT_FSIZE, set from outside with
`prlimit --pid`) makes every write that grows a file fail with EFBIG, as a full disk fails with
ENOSPC.

  serve_storage_test.py STATION SIMRIG

Checks: with a run going, the limit set -> the daemon lives (SIGXFSZ ignored), /api/status says
`fault` naming the storage, every sample committed before is still there, a start is refused with
503 naming the storage (never 202, nor 409); the limit lifted -> the failed run is closed ('aborted' with a `run_failed`
event naming the reason) within seconds, and a new run starts (202 with its id), records ticks
and stops cleanly. Exit 0 ok, 1 failure, 77 without prlimit.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import serve_http_test as h  # noqa: E402  (the serve test's helpers)


def prlimit_fsize(pid, soft):
    subprocess.run(["prlimit", "--pid", str(pid), "--fsize=%s:" % soft], check=True)


def main():
    if shutil.which("prlimit") is None:
        print("SKIP: prlimit (util-linux) is not installed")
        return 77
    station, simrig = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    work = tempfile.mkdtemp(prefix="serve-storage-")
    rig_cfg = open(os.path.join(work, "rig.toml"), "w")
    rig = subprocess.Popen([simrig, "--gyros", "2", "--can-socket", os.path.join(work, "can.sock")],
                           stdout=rig_cfg, stderr=subprocess.DEVNULL, cwd=work)
    procs = [rig]
    try:
        h.wait_for(lambda: os.path.getsize(os.path.join(work, "rig.toml")) > 200, 10, "simrig")
        time.sleep(0.3)
        serve, base = h.start_serve(station, work, "serve.log")
        procs.append(serve)
        token = open(os.path.join(work, "s.db.token")).read().strip()
        h.wait_for(lambda: h.status(base)["chamber"], 10, "the idle rig read")
        code, body = h.request(base, "POST", "/api/runs", token, {"protocol": "paper"})
        h.check(code == 202 and body.get("run_id", 0) > 0, "start: 202, got %d %s" % (code, body))
        run1 = body.get("run_id", 0)
        h.wait_for(lambda: h.status(base)["ticks"] >= 3, 15, "three ticks")

        # No file may grow any more: the next commit fails.
        sizes = [os.path.getsize(os.path.join(work, f)) for f in ("s.db", "s.db-wal")
                 if os.path.exists(os.path.join(work, f))]
        prlimit_fsize(serve.pid, max(sizes) + 1)
        st = h.wait_for(lambda: (lambda s: s if s["state"] == "fault" and "storage" in
                                 s.get("fault", "") else None)(h.status(base)), 15,
                        "status 'fault' naming the storage")
        h.check(serve.poll() is None, "the daemon lives on a failed write (no SIGXFSZ death)")
        h.check(st and str(run1) in st.get("fault", ""), "the fault names the run: %s" % st)
        kept = h.samples_of(work, run1)
        h.check(kept >= 3 * 2, "committed samples kept: %d" % kept)
        h.check(h.run_state(work, run1) == "running", "the run cannot be closed while full")
        code, body = h.request(base, "POST", "/api/runs", token, {"protocol": "paper"})
        # 503 as README and schemas/api.md say (issue 34 point 11): the station cannot record, a
        # trouble of the server's own, not a conflict with the run the client could resolve (409).
        h.check(code == 503 and "storage" in str(body), "a start while full is 503 naming the "
                "storage, got %d %s" % (code, body))

        # Room again: the run is closed with its reason, and the service starts runs again.
        prlimit_fsize(serve.pid, "unlimited")
        h.wait_for(lambda: h.run_state(work, run1) == "aborted", 10, "the failed run closed")
        ev = h.db_query(work, "SELECT message FROM events WHERE run_id = ? AND kind = "
                        "'run_failed'", run1)
        h.check(ev is not None and ev[0], "a run_failed event with the reason: %s" % (ev,))
        h.check(h.samples_of(work, run1) >= kept, "no committed sample lost")
        code, body = h.request(base, "POST", "/api/runs", token, {"protocol": "paper"})
        h.check(code == 202 and body.get("run_id", 0) > run1, "start after recovery: 202 with a "
                "new run id, got %d %s" % (code, body))
        run2 = body.get("run_id", 0)
        h.wait_for(lambda: h.samples_of(work, run2) >= 3 * 2, 15, "ticks of the new run")
        code, _ = h.request(base, "POST", "/api/runs/%d/stop" % run2, token)
        h.wait_for(lambda: h.run_state(work, run2) == "stopped", 15, "the new run stopped")
        serve.terminate()
        h.check(serve.wait(15) == 0, "SIGTERM: exit 0")
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait()
    if h.FAILURES:
        print("%d failure(s); logs in %s" % (len(h.FAILURES), work))
        return 1
    print("serve storage: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
