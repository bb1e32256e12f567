#!/usr/bin/env bash
# Issue 20: simrig on the wall clock speaking each chamber and table dialect on its real transport,
# and `station probe` through the configuration simrig printed: exit 0, and each device's line
# names its model and what it read (units, identity).
# usage: probe_dialects.sh BUILD_DIR
set -u
build=${1:?usage: probe_dialects.sh BUILD_DIR}
tmp=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null; rm -rf "$tmp"' EXIT
failed=0
for pair in "watlow_f4 acutrol3000" "watlow_f4t acutrol3000" "watlow_f4t_map2 generic_plc" \
  "watlow_f4p acutrol3000" "espec_p300 acutrol3000" "generic_plc generic_plc"; do
  set -- $pair
  "$build/sim_devices/simrig" --gyros 1 --can-socket "$tmp/$1.sock" --chamber "$1" \
    --turntable "$2" >"$tmp/$1.toml" 2>"$tmp/$1.err" &
  pid=$!
  for _ in $(seq 100); do grep -q SIM-0001 "$tmp/$1.toml" && break; sleep 0.05; done
  sleep 0.2
  out=$("$build/station/station" probe --config "$tmp/$1.toml" 2>&1)
  rc=$?
  kill "$pid"
  wait "$pid" 2>/dev/null
  if [[ $rc -ne 0 ]] || ! grep -q "^chamber .*model $1: .*units C" <<<"$out" ||
    ! grep -q "^turntable .*model $2" <<<"$out" || ! grep -q "model = \"$1\"" "$tmp/$1.toml"; then
    echo "FAIL $1 + $2 (exit $rc):"
    echo "$out"
    failed=1
  else
    echo "ok   $1 + $2"
  fi
done
exit $failed
