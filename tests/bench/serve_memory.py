#!/usr/bin/env python3
"""What an idle `station serve` holds, mapping by mapping (docs/BENCHMARKS.md, issue 37).

  serve_memory.py STATION SIMRIG [--seconds 60] [--env NAME=VALUE ...] [--top 12]

Starts simrig (8 gyros) and `station serve` on it as tests/bench/http_bench.py does, waits
SECONDS idle, then reads /proc/PID/smaps_rollup and /proc/PID/smaps and prints RSS, PSS and
USS (Private_Clean + Private_Dirty: what this process alone costs the machine) in total and per
file: RSS counts the clean pages of shared libraries that every process mapping them shares, so
PSS (each shared page divided by the number of processes mapping it) and USS are the honest
per-process figures; the dirty pages (heap, stacks, the libraries' relocated data) are what
the process alone costs however many others run. `--env` runs the station with an environment variable set (e.g.
MALLOC_ARENA_MAX=1, LD_BIND_NOW=1) to compare.
"""
import collections
import os
import re
import subprocess
import sys
import tempfile
import time

FIELDS = ("Rss", "Pss", "Shared_Clean", "Shared_Dirty", "Private_Clean", "Private_Dirty",
          "Anonymous")


def smaps(pid):
    """Per mapping name: the sums of FIELDS in kB."""
    per = collections.defaultdict(lambda: dict.fromkeys(FIELDS, 0))
    name = None
    for line in open("/proc/%d/smaps" % pid):
        head = re.match(r"^[0-9a-f]+-[0-9a-f]+ \S+ \S+ \S+ \S+\s*(.*)$", line)
        if head:
            name = head.group(1) or "[anon]"
            continue
        m = re.match(r"^(\w+):\s+(\d+) kB", line)
        if m and m.group(1) in FIELDS:
            per[name][m.group(1)] += int(m.group(2))
    return per


def rollup(pid):
    out = {}
    for line in open("/proc/%d/smaps_rollup" % pid):
        m = re.match(r"^(\w+):\s+(\d+) kB", line)
        if m:
            out[m.group(1)] = int(m.group(2))
    return out


def measure(station, simrig, seconds, env):
    work = tempfile.mkdtemp(prefix="serve-mem-")
    rig = subprocess.Popen([simrig, "--gyros", "8", "--can-socket", work + "/can.sock"],
                           cwd=work, stdout=open(work + "/rig.toml", "w"),
                           stderr=subprocess.DEVNULL)
    time.sleep(1.5)
    p = subprocess.Popen([station, "serve", "--config", "rig.toml", "--db", "s.db", "--http",
                          "127.0.0.1:0"], cwd=work, stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, text=True, env=dict(os.environ, **env))
    try:
        p.stdout.readline()
        time.sleep(seconds)
        threads = len(os.listdir("/proc/%d/task" % p.pid))
        return rollup(p.pid), smaps(p.pid), threads
    finally:
        for x in (p, rig):
            x.kill()
            x.wait()


def mb(kb):
    return "%.1f" % (kb / 1024)


def main():
    station, simrig = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    args = sys.argv[3:]
    seconds = int(args[args.index("--seconds") + 1]) if "--seconds" in args else 60
    top = int(args[args.index("--top") + 1]) if "--top" in args else 12
    env = dict(args[i + 1].split("=", 1) for i, a in enumerate(args) if a == "--env")
    total, per, threads = measure(station, simrig, seconds, env)
    uss = total["Private_Clean"] + total["Private_Dirty"]
    print("serve idle %d s%s: RSS %s MB, PSS %s MB, USS %s MB (anonymous %s MB), %d threads"
          % (seconds, "".join(" " + k + "=" + v for k, v in env.items()), mb(total["Rss"]),
             mb(total["Pss"]), mb(uss), mb(total["Anonymous"]), threads))
    print("dirty (written by this process: its own whatever else runs) %s MB"
          % mb(total["Private_Dirty"] + total["Shared_Dirty"]))
    print("%-40s %7s %7s %7s %7s %7s" % ("mapping", "RSS", "PSS", "shared", "clean", "dirty"))
    rows = sorted(per.items(), key=lambda kv: -kv[1]["Rss"])
    for name, f in rows[:top]:
        print("%-40s %7s %7s %7s %7s %7s" % (os.path.basename(name)[:40], mb(f["Rss"]),
                                             mb(f["Pss"]), mb(f["Shared_Clean"]),
                                             mb(f["Private_Clean"]),
                                             mb(f["Private_Dirty"] + f["Shared_Dirty"])))
    rest = rows[top:]
    print("%-40s %7s %7s %7s %7s %7s" % (
        "%d others" % len(rest), *(mb(sum(f[k] for _, f in rest)) for k in (
            "Rss", "Pss", "Shared_Clean", "Private_Clean", "Private_Dirty"))))


if __name__ == "__main__":
    main()
