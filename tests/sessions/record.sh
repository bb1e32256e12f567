#!/usr/bin/env bash
# Re-records the shipped sessions (tests/sessions/*/) with the simulated rig, for when the
# station's behaviour changed on purpose: `tests/sessions/record.sh build/station/station`.
# Each session is the protocol session_cycle.toml (the acceptance_* ones: session_acceptance.toml)
# on one simulated gyro (seed 1), with faults injected at fixed ticks; logs and result are
# gzip-compressed (read as .gz transparently).
set -euo pipefail
station=${1:?usage: record.sh PATH/TO/station}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
protocol=session_cycle.toml
trap 'rm -rf "$tmp"' EXIT
run_sim() {
  local name=$1
  shift
  "$station" run --sim --gyros 1 --seed 1 --db "$tmp/$name.db" \
    --protocol "$here/$protocol" --record "$here/$name" "$@" >/dev/null
}
finish() {
  gzip -9 -n "$here/$1"/*.log "$here/$1/result.json" "$here/$1/digest.txt"
  "$station" replay "$here/$1"
}
record() {
  local name=$1
  shift
  rm -rf "${here:?}/$name"
  run_sim "$name" --new "$@"
  finish "$name"
}
record happy_cycle
# The door opens mid-record: safe hold (gyro power off, amber), closes a minute later.
record door_mid_record --fault "1800:door open" --fault "1860:door close"
# A chamber that stops answering for 2 s of wall time, CAN frames lost and sent twice, the
# turntable dropping its connections once.
record link_faults --fault "1500:chamber stall 2" --fault "2000:can drop 3" \
  --fault "2300:can duplicate 5" --fault "2600:table disconnect"
# One session per device dialect (docs/DEVICES.md), each device served by its simulator face on
# its real transport: Watlow F4 (station-made ramps), F4T Data Map 1 + ACUTROL3000 (replies in the
# error/length header) with a chamber stall and a table disconnect, F4T in F4-compatibility map,
# F4P, ESPEC P300 (ascii.log) with error replies + ACUTROL3000 (bare CR LF replies).
record dialect_f4 --chamber watlow_f4
record dialect_f4t_acutrol --chamber watlow_f4t --turntable acutrol3000 --acutrol-framing header \
  --fault "400:table disconnect 0.02" --fault "1500:chamber stall 2"
record dialect_f4t_map2 --chamber watlow_f4t_map2
record dialect_f4p --chamber watlow_f4p
record dialect_p300_acutrol --chamber espec_p300 --turntable acutrol3000 \
  --fault "2300:chamber exception 4 5"
# The daemon killed (SIGKILL) before tick 1230, mid-record and mid-bin, and run again: it
# resumes after its last committed tick (1199: the simulation commits once a minute).
rm -rf "${here:?}/killed_resumed"
run_sim killed_resumed --new --fault "1230:kill" 2>/dev/null || [ $? -eq 137 ]
run_sim killed_resumed 2>/dev/null
finish killed_resumed
# The operator's Ctrl-C (SIGINT, raised by the daemon itself before tick 2400): the run ends
# 'stopped' after that tick, bins and fits what it recorded; the replay stops where it stopped.
record stopped_sigint --fault "2400:sigint"
# The API's abort on a run paced at 100x (POST /api/runs/1/abort about 20 s of wall time in):
# 'aborted', no bins, no fit. The tick it took effect is whichever the wall clock chose; the
# recording says which.
rm -rf "${here:?}/aborted_api"
port=$((20000 + RANDOM % 20000))
run_sim aborted_api --new --speed 100 --http "127.0.0.1:$port" &
daemon=$!
sleep 20
curl -fsS -X POST --data "" -H "Authorization: Bearer $(cat "$tmp/aborted_api.db.token")" \
  "http://127.0.0.1:$port/api/runs/1/abort" >/dev/null
wait "$daemon"
finish aborted_api
# Issue 36: the acceptance steps at room temperature (power cycles through the relays, a rate
# ladder, positions): the table's rate and angle demands and its read-back on the wire.
protocol=session_acceptance.toml
record acceptance_room
# The turntable's drive faults in the middle of the ladder for 60 s: a safe hold (table stopped,
# gyros unpowered), the points it cut left out, the ladder resumed after it.
record acceptance_ladder_fault --fault "1420:table fault on" --fault "1480:table fault off"
