#!/usr/bin/env bash
# Coverage of the reported 1-sigma uncertainties through the whole daemon (docs/UNCERTAINTY.md):
# `station run --sim --gyros 8` for seeds 1..6 (48 gyros, ~2.5 min), then the share of gyros
# whose true k1 / k0 lies within the reported std_errors and within std_errors_ols.
# Usage: scripts/daemon_coverage.sh [build/station/station]
set -euo pipefail
station=${1:-build/station/station}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for s in 1 2 3 4 5 6; do
  "$station" run --sim --gyros 8 --seed "$s" --db "$tmp/s$s.db" --json 2>/dev/null >"$tmp/s$s.json"
done
python3 - "$tmp" <<'P'
import json, sys
n = hits = 0
c = {"k1": 0, "k0": 0, "k1_ols": 0, "k0_ols": 0}
for s in range(1, 7):
    for g in json.load(open(f"{sys.argv[1]}/s{s}.json"))["gyros"]:
        n += 1
        for k in ("k1", "k0"):
            err = abs(g["fitted"][k] - g["true"][k])
            c[k] += err <= g["std_errors"][k]
            c[k + "_ols"] += err <= g["std_errors_ols"][k]
print(f"daemon coverage over {n} gyros: k1 {c['k1']/n:.3f} (OLS {c['k1_ols']/n:.3f}), "
      f"k0 {c['k0']/n:.3f} (OLS {c['k0_ols']/n:.3f})")
P
