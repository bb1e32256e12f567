#!/usr/bin/env bash
# Issue 35: the README's rig walk-through ("A simulated rig in ten minutes") works as written.
# The commands between its <!-- walkthrough --> and <!-- /walkthrough --> lines are run as one
# bash script, with only where things go changed: build/ is BUILD_DIR, /tmp/ a scratch directory
# (simrig's CAN socket there too, so a parallel test's simrig is not disturbed). Then what the
# README says they give: probe answers, the demo run of the scanned serials completes and fits
# every gyro, the report exists, the release is exported. About 9 minutes of wall time (the
# demo protocol on simrig's wall clock).
# usage: readme_walkthrough.sh SOURCE_DIR BUILD_DIR
set -u
src=${1:?usage: readme_walkthrough.sh SOURCE_DIR BUILD_DIR}
build=${2:?usage: readme_walkthrough.sh SOURCE_DIR BUILD_DIR}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
block=$(sed -n '/^<!-- walkthrough -->$/,/^<!-- \/walkthrough -->$/p' "$src/README.md" |
  grep '^    ' | sed 's/^    //')
if [[ -z $block ]]; then
  echo "FAIL: README.md has no <!-- walkthrough --> block"
  exit 1
fi
script=$(sed -e "s#build/#$build/#g" -e "s#/tmp/#$tmp/#g" \
  -e "s#sim_devices/simrig #sim_devices/simrig --can-socket $tmp/can.sock #" <<<"$block")
# A failing command must not leave the walk-through's simrig running.
{ echo "trap 'kill \$(jobs -p) 2>/dev/null' EXIT"; echo "$script"; } >"$tmp/walkthrough.sh"
(cd "$tmp" && bash -e "$tmp/walkthrough.sh") >"$tmp/out.log" 2>&1
rc=$?
cat "$tmp/out.log"
failed=0
check() {  # check CONDITION WHAT
  if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; failed=1; fi
}
check '[[ $rc -eq 0 ]]' "the walk-through's commands exit 0 (exit $rc)"
check 'grep -q "^all devices answered" "$tmp/out.log"' "probe: all devices answered"
check 'grep -q "^run 1 (completed)" "$tmp/out.log"' "run 1 (completed)"
check 'grep -q "run 1 (completed)" "$tmp/out.log" && grep -q "^GX-0102 " "$tmp/out.log"' \
  "the summary names the scanned serials"
for serial in GX-0101 GX-0102; do
  check '"$build/station/station" history --db "$tmp/demo.db" --serial $serial --json |
    grep -q "\"fit_id\""' "a fit of $serial stored"
done
check 'ls "$tmp"/demo-report/*.html >/dev/null 2>&1' "the report written"
check 'grep -q "gyro_tc" "$tmp/out.log"' "the released calibration exported as C"
exit $failed
