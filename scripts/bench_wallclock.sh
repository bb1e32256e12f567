#!/usr/bin/env bash
# The daemon on the wall clock at 1 Hz with N simulated gyros (default 16): simrig serves the
# rig, `station run --config` drives it for DURATION seconds (default 120); prints the station
# process's CPU use (utime+stime over wall time, from /proc/PID/stat) and its peak resident
# memory (VmHWM). Figures go to docs/BENCHMARKS.md.
set -euo pipefail
cd "$(dirname "$0")/.."
GYROS=${1:-16}
DURATION=${2:-120}
BUILD_DIR=${BUILD_DIR:-build}
work=$(mktemp -d)
trap 'kill $SIMRIG_PID 2>/dev/null || true; rm -rf "$work"' EXIT

"$BUILD_DIR/sim_devices/simrig" --gyros "$GYROS" --can-socket "$work/can.sock" >"$work/rig.toml" 2>"$work/simrig.log" &
SIMRIG_PID=$!
for _ in $(seq 50); do grep -q '^\[\[slot\]\]' "$work/rig.toml" 2>/dev/null && break; sleep 0.1; done

"$BUILD_DIR/station/station" run --config "$work/rig.toml" --protocol paper --db "$work/wc.db" \
  --log-file "$work/station.log" >/dev/null 2>&1 &
STATION_PID=$!
sleep 5  # start-up excluded from the steady-state figure
read -r -a s0 < <(cut -d' ' -f14,15 "/proc/$STATION_PID/stat")
t0=$(date +%s.%N)
sleep "$DURATION"
read -r -a s1 < <(cut -d' ' -f14,15 "/proc/$STATION_PID/stat")
t1=$(date +%s.%N)
hwm=$(awk '/VmHWM/ {print $2}' "/proc/$STATION_PID/status")
kill -TERM "$STATION_PID"
wait "$STATION_PID" || true
ticks=$(getconf CLK_TCK)
cpu=$(echo "(${s1[0]} + ${s1[1]} - ${s0[0]} - ${s0[1]}) / $ticks" | bc -l)
wall=$(echo "$t1 - $t0" | bc -l)
samples=$(sqlite3 "$work/wc.db" "select count(*) from samples")
printf 'gyros %d, %.0f s at 1 Hz: CPU %.3f s = %.2f %% of a core; peak RSS %d KiB; %d samples stored\n' \
  "$GYROS" "$wall" "$cpu" "$(echo "100 * $cpu / $wall" | bc -l)" "$hwm" "$samples"
