#!/usr/bin/env python3
"""What serving the page costs the 1 Hz loop (docs/BENCHMARKS.md, "HTTP service").

  http_bench.py STATION SIMRIG [--seconds 20]

1. Tick duration with 0 and with 3 event-stream clients attached: `station run --sim --gyros 8
   --speed 1000 --http 127.0.0.1:0`; after a warm-up the daemon's own histogram
   (station_tick_duration_seconds, wall time of each tick: devices, safety, store, hub) is read
   from /metrics twice and the difference gives the mean and the bucket quantiles of the ticks
   in between. The clients read and parse every message.
2. /api/status latency: 500 sequential GETs on one keep-alive connection, during the run.
3. `station serve` idle on simrig for SECONDS: CPU share of one core (utime+stime from
   /proc/PID/stat) and resident memory (VmRSS, VmHWM).
"""
import http.client
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time


def metrics(port):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.request("GET", "/metrics")
    text = c.getresponse().read().decode()
    buckets, total, count = {}, 0.0, 0.0
    for line in text.splitlines():
        m = re.match(r'station_tick_duration_seconds_bucket\{le="([^"]+)"\} (\S+)', line)
        if m:
            buckets[float(m.group(1))] = float(m.group(2))
        elif line.startswith("station_tick_duration_seconds_sum "):
            total = float(line.split()[1])
        elif line.startswith("station_tick_duration_seconds_count "):
            count = float(line.split()[1])
    return buckets, total, count


def quantile(b0, b1, q):
    n = b1[float("inf")] - b0[float("inf")]
    for le in sorted(b1):
        if b1[le] - b0.get(le, 0) >= q * n:
            return le
    return float("inf")


def stream_client(port, stop, counter):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    c.request("GET", "/api/events/stream")
    r = c.getresponse()
    while not stop.is_set():
        line = r.fp.readline()
        if not line:
            break
        if line.startswith(b"data: "):
            counter[0] += 1


def start_run(station, work):
    p = subprocess.Popen([station, "run", "--sim", "--gyros", "8", "--speed", "1000", "--http",
                          "127.0.0.1:0", "--db", "b.db", "--new"], cwd=work,
                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    line = p.stdout.readline()
    return p, int(line.rsplit(":", 1)[1].strip("/\n"))


def tick_bench(station, streams):
    work = tempfile.mkdtemp(prefix="http-bench-")
    p, port = start_run(station, work)
    stop, counters, threads = threading.Event(), [], []
    try:
        for _ in range(streams):
            counters.append([0])
            t = threading.Thread(target=stream_client, args=(port, stop, counters[-1]), daemon=True)
            t.start()
            threads.append(t)
        time.sleep(3)
        b0, s0, n0 = metrics(port)
        time.sleep(10)
        b1, s1, n1 = metrics(port)
        lat = []
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        for _ in range(500):
            t0 = time.perf_counter()
            c.request("GET", "/api/status")
            c.getresponse().read()
            lat.append(time.perf_counter() - t0)
        return {"ticks": n1 - n0, "mean_ms": 1e3 * (s1 - s0) / (n1 - n0),
                "p50_le_ms": 1e3 * quantile(b0, b1, 0.5), "p99_le_ms": 1e3 * quantile(b0, b1, 0.99),
                "messages": [x[0] for x in counters],
                "status_p50_ms": 1e3 * statistics.median(lat),
                "status_p99_ms": 1e3 * sorted(lat)[int(0.99 * len(lat))]}
    finally:
        stop.set()
        p.kill()
        p.wait()


def idle_bench(station, simrig, seconds):
    work = tempfile.mkdtemp(prefix="serve-idle-")
    rig = subprocess.Popen([simrig, "--gyros", "8", "--can-socket", work + "/can.sock"], cwd=work, stdout=open(work + "/rig.toml", "w"),
                           stderr=subprocess.DEVNULL)
    time.sleep(1.5)
    p = subprocess.Popen([station, "serve", "--config", "rig.toml", "--db", "s.db", "--http",
                          "127.0.0.1:0"], cwd=work, stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, text=True)
    try:
        p.stdout.readline()
        time.sleep(3)
        hz = os.sysconf("SC_CLK_TCK")

        def cpu():
            f = open("/proc/%d/stat" % p.pid).read().rsplit(")", 1)[1].split()
            return (int(f[11]) + int(f[12])) / hz

        c0, t0 = cpu(), time.monotonic()
        time.sleep(seconds)
        c1, t1 = cpu(), time.monotonic()
        status = open("/proc/%d/status" % p.pid).read()
        rss = int(re.search(r"VmRSS:\s+(\d+)", status).group(1)) / 1024
        hwm = int(re.search(r"VmHWM:\s+(\d+)", status).group(1)) / 1024
        return {"cpu_share_pct": 100 * (c1 - c0) / (t1 - t0), "rss_mb": rss, "hwm_mb": hwm}
    finally:
        for x in (p, rig):
            x.kill()
            x.wait()


def main():
    station, simrig = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    seconds = int(sys.argv[sys.argv.index("--seconds") + 1]) if "--seconds" in sys.argv else 20
    for n in (0, 3):
        r = tick_bench(station, n)
        print("tick, %d stream clients: %d ticks, mean %.3f ms, p50 <= %.1f ms, p99 <= %.1f ms; "
              "messages read per client %s; /api/status p50 %.2f ms, p99 %.2f ms"
              % (n, r["ticks"], r["mean_ms"], r["p50_le_ms"], r["p99_le_ms"], r["messages"],
                 r["status_p50_ms"], r["status_p99_ms"]), flush=True)
    r = idle_bench(station, simrig, seconds)
    print("serve idle on simrig (8 gyros), %d s: CPU %.2f %% of one core, RSS %.1f MB (peak %.1f MB)"
          % (seconds, r["cpu_share_pct"], r["rss_mb"], r["hwm_mb"]))


if __name__ == "__main__":
    main()
