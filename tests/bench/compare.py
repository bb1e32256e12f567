#!/usr/bin/env python3
"""Two builds' benchmarks interleaved on one machine: the ratio of each figure (issue 37).

This machine is noisy (2 shared cores): a figure measured an hour ago is no reference for one
measured now. So every benchmark both programs have is run alternately, A B A B ..., one process
per run, and each program's figure is the median of its runs; the ratio NEW / OLD of medians
is printed. A benchmark is not a test: this prints, it never fails on a ratio.

Usage: compare.py OLD_BENCH NEW_BENCH [--rounds N] [--filter REGEX] [--json OUT]
         [--old-name REV] [--new-name HEAD]
"""
import argparse
import json
import re
import statistics
import subprocess
import sys
import tempfile


def listed(binary, pattern):
    out = subprocess.run([binary, "--benchmark_list_tests", "--benchmark_filter=" + pattern],
                         check=True, capture_output=True, text=True).stdout
    return [line.strip() for line in out.splitlines() if line.strip()]


def run_one(binary, name):
    """One process running one benchmark; returns (real time, unit) of its first entry."""
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        subprocess.run([binary, "--benchmark_filter=^" + re.escape(name) + "$",
                        "--benchmark_out=" + out.name, "--benchmark_out_format=json"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        entries = json.load(open(out.name))["benchmarks"]
    runs = [e for e in entries if e.get("run_type", "iteration") == "iteration"]
    if not runs:
        raise RuntimeError("%s: no figure for %s" % (binary, name))
    return runs[0]["real_time"], runs[0]["time_unit"]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("old")
    p.add_argument("new")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--filter", default=".")
    p.add_argument("--json")
    p.add_argument("--old-name", default="old")
    p.add_argument("--new-name", default="new")
    a = p.parse_args()
    if a.rounds < 1:
        print("compare.py: --rounds must be at least 1", file=sys.stderr)
        return 2
    old_names, new_names = listed(a.old, a.filter), listed(a.new, a.filter)
    common = [n for n in new_names if n in old_names]
    for n in sorted(set(old_names) ^ set(new_names)):
        print("only in %s: %s" % (a.old_name if n in old_names else a.new_name, n))
    rows = []
    print("%-58s %14s %14s %8s" % ("benchmark (median of %d, interleaved)" % a.rounds,
                                   a.old_name, a.new_name, "ratio"))
    for name in common:
        old_t, new_t = [], []
        for _ in range(a.rounds):
            t, unit = run_one(a.old, name)
            old_t.append(t)
            t, unit = run_one(a.new, name)
            new_t.append(t)
        om, nm = statistics.median(old_t), statistics.median(new_t)
        rows.append({"benchmark": name, "unit": unit, "old": old_t, "new": new_t,
                     "old_median": om, "new_median": nm, "ratio": nm / om if om else None})
        print("%-58s %11.4g %-2s %11.4g %-2s %8.3f" % (name[:58], om, unit, nm, unit,
                                                      nm / om if om else float("nan")), flush=True)
    if a.json:
        json.dump({"old": a.old_name, "new": a.new_name, "rounds": a.rounds, "rows": rows},
                  open(a.json, "w"), indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
