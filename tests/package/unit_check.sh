#!/usr/bin/env bash
# The shipped systemd units as installed, without installing them: `cmake --install` into a
# staging root (DESTDIR), the system's own targets and sockets copied beside them (the default
# dependencies verify resolves), then
#   systemd-analyze verify --root   : no warning at all (ExecStart exists and is executable, ...)
#   systemd-analyze security --offline --threshold : exposure at most MAX (0..100; 21 = "2.1 OK")
# and the hardening the README promises, key by key.
#   unit_check.sh BUILD_DIR STAGE_DIR MAX_EXPOSURE
set -euo pipefail
build=$1 stage=$2 max=$3
command -v systemd-analyze >/dev/null || { echo "SKIP: no systemd-analyze (package systemd)"; exit 77; }
rm -rf "$stage"
DESTDIR="$stage" cmake --install "$build" --prefix /usr >/dev/null
units="$stage/usr/lib/systemd/system"
for f in /lib/systemd/system/*.target /lib/systemd/system/*.slice /lib/systemd/system/*.socket; do
  cp -n "$f" "$units/" 2>/dev/null || true
done
fail=0
out=$(systemd-analyze verify --root="$stage" "$units/gyro-station.service" \
  "$units/gyro-station-simrig.service" 2>&1) || fail=1
if [[ -n $out || $fail -ne 0 ]]; then echo "FAIL: systemd-analyze verify: $out"; exit 1; fi
echo "ok: systemd-analyze verify (both units)"
for u in gyro-station.service gyro-station-simrig.service; do
  if ! systemd-analyze security --offline=true --root="$stage" --threshold="$max" "$u" \
    >"$stage/$u.security" 2>&1; then
    echo "FAIL: $u: $(tail -1 "$stage/$u.security") (threshold $max)"
    exit 1
  fi
  echo "ok: $u: $(grep -o 'Overall exposure level.*' "$stage/$u.security")"
done
for key in User=gyro-station NoNewPrivileges=yes ProtectSystem=strict ProtectHome=yes PrivateTmp=yes \
  "ReadWritePaths=/var/lib/gyro-station /run/lock" CapabilityBoundingSet= DevicePolicy=closed \
  Type=notify WatchdogSec=10 Restart=on-failure RestartPreventExitStatus=2; do
  grep -qx -- "$key" "$units/gyro-station.service" || { echo "FAIL: gyro-station.service lacks $key"; exit 1; }
done
echo "ok: the promised hardening keys"
