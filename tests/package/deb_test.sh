#!/usr/bin/env bash
# The Debian package on this machine, as an administrator meets it (README, "Install on a station
# PC"). Root only, and it changes the machine (installs, creates a user, removes and purges):
# for CI or a throwaway machine. `scripts/dev package-test` builds the package and runs this.
#
#   deb_test.sh PATH/gyro-station_VERSION_ARCH.deb
#
# 0. lintian on the .deb: clean (remaining tags overridden with their reasons).
# 1. apt-get install ./deb: --version; manual pages (station-SUB(1) per subcommand); copyright, changelog and the README's docs/*.md shipped; the service user in dialout; /var/lib/gyro-station owned
#    by it 0750; the conffile; the unit enabled (the wants link) and not started.
# 2. From the installed files only (an empty directory, PATH=/usr/bin:/bin): simrig, then
#    `station probe --config` against it, then `station run --sim` (the main job), as the
#    service user.
# 3. With systemd: the host's when it is PID 1, else a systemd booted in its own PID and mount
#    namespaces (skipped with a message when that cannot start). gyro-station-simrig and the
#    hardened gyro-station start and answer /api/status; a run started over the API survives
#    an upgrade (to the same package as version V+upgradetest1: the postinst's SIGUSR1
#    hand-over, the same run resumed by the restarted service); `systemctl stop` ends it
#    'stopped'; a broken configuration fails the unit once (no restart loop).
# 4. apt-get remove keeps the conffile and the data; purge removes what the package created and
#    keeps the database (and the user owning it); with no data, purge leaves nothing at all.
set -uo pipefail
DEB=$(realpath "$1")
FAILS=0
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
ok() { echo "ok: $*"; }
check() { if eval "$1"; then ok "$2"; else fail "$2"; fi; }
[[ $(id -u) -eq 0 ]] || { echo "deb_test: needs root (it installs the package)"; exit 77; }
if dpkg-query -W -f='${Status}' gyro-station 2>/dev/null | grep -q installed; then
  echo "deb_test: gyro-station is already installed here; purge it first"; exit 2
fi
export DEBIAN_FRONTEND=noninteractive
WORK=$(mktemp -d /var/tmp/deb-test.XXXXXX)
chmod 0755 "$WORK"
NS_PID=""
IN=()        # how to run a command where systemd is (nsenter into the namespaced one)
HAVE_SYSTEMD=0
cleanup() { [[ -n $NS_PID ]] && kill -KILL "$NS_PID" 2>/dev/null; }
trap cleanup EXIT

leftovers() {  # what remains of the package on the machine, one path or entry per line
  ls -d /etc/gyro-station /usr/share/gyro-station /usr/share/doc/gyro-station /usr/bin/station \
    /usr/bin/simrig /usr/lib/systemd/system/gyro-station*.service \
    /usr/lib/udev/rules.d/60-gyro-station.rules /etc/systemd/system/*/gyro-station*.service \
    /var/lib/systemd/deb-systemd-helper-enabled/*gyro-station* \
    /var/lib/systemd/deb-systemd-helper-masked/*gyro-station* /var/lib/gyro-station 2>/dev/null
  getent passwd gyro-station | sed 's/^/passwd: /'
  getent group gyro-station | sed 's/^/group: /'
}

lintian_check() {
  # lintian on the built package: clean, each remaining tag overridden with its reason
  # (station/package/debian/lintian-overrides).
  if ! command -v lintian >/dev/null; then fail "lintian is not installed (scripts/dev installs it)"; return; fi
  local out
  out=$(lintian --tag-display-limit 0 "$DEB" 2>&1 | grep -v "running with root privileges")
  check '[[ -z $out ]]' "lintian $(basename "$DEB"): ${out:-clean}"
}

install_checks() {
  apt-get install -y "$DEB" >"$WORK/install.log" 2>&1 || { fail "apt-get install (log below)"; cat "$WORK/install.log"; exit 1; }
  ok "apt-get install ./$(basename "$DEB")"
  local v
  v=$(/usr/bin/station --version)
  check '[[ $v == "station $(dpkg-query -W -f="\${Version}" gyro-station)" ]]' "station --version: $v"
  check '[[ -f /usr/share/man/man1/station.1.gz && -f /usr/share/man/man1/simrig.1.gz ]] && grep -q "^serve" <<<"$(zcat /usr/share/man/man1/station.1.gz)"' \
    "manual pages station(1) and simrig(1), made from --help"
  # Issue 23 point 9: every subcommand `station --help` lists has its page station-SUB(1), found
  # by man, made from its --help with an EXIT STATUS section, and named in station(1).
  local subs sub page bad_pages=""
  subs=$(/usr/bin/station --help | sed -n '/^[Ss][Uu][Bb][Cc][Oo][Mm][Mm][Aa][Nn][Dd][Ss]:/,$p' |
    awk 'NR > 1 && /^  [a-z]/ {print $1}')
  for sub in $subs; do
    page=$(man -w "station-$sub" 2>/dev/null)
    if [[ -z $page ]] || ! zcat "$page" | grep -q '^\.SH "\?EXIT STATUS' ||
      ! zcat "$page" | grep -q "^\.SH OPTIONS" ||
      ! zcat /usr/share/man/man1/station.1.gz | grep -q "station-$sub"; then
      bad_pages+=" $sub"
    fi
  done
  check '[[ -n $subs && -z $bad_pages ]]' \
    "man station-SUB for each of $(wc -w <<<"$subs") subcommands, with EXIT STATUS, in station(1) SEE ALSO: ${bad_pages:-all}"
  # Debian policy 12.5 / 12.7: copyright and changelog; the documents the README links to.
  check '[[ -f /usr/share/doc/gyro-station/copyright && -f /usr/share/doc/gyro-station/changelog.gz ]]' \
    "copyright and changelog.gz in /usr/share/doc/gyro-station"
  local missing_docs
  missing_docs=$(grep -o "docs/[A-Z_]*\.md" /usr/share/doc/gyro-station/README.md | sort -u |
    while read -r d; do [[ -f /usr/share/doc/gyro-station/$d ]] || echo "$d"; done)
  check '[[ -z $missing_docs ]]' "every docs/*.md the installed README names is shipped: missing ${missing_docs:-none}"
  check 'id -nG gyro-station | grep -qw dialout' "the service user is in dialout: $(id -nG gyro-station)"
  check '[[ $(stat -c "%U:%G %a" /var/lib/gyro-station) == "gyro-station:gyro-station 750" ]]' \
    "/var/lib/gyro-station: $(stat -c '%U:%G %a' /var/lib/gyro-station)"
  check '[[ $(getent passwd gyro-station | cut -d: -f7) == /usr/sbin/nologin ]]' "no login shell"
  check 'dpkg-query -W -f="\${Conffiles}" gyro-station | grep -q "/etc/gyro-station/station.toml"' \
    "/etc/gyro-station/station.toml is a conffile"
  check '[[ -L /etc/systemd/system/multi-user.target.wants/gyro-station.service ]]' "the unit is enabled"
  check '! [[ -e /etc/systemd/system/multi-user.target.wants/gyro-station-simrig.service ]]' \
    "the simulated rig's unit is not enabled"
}

installed_files_only() {  # simrig, probe, run --sim from /usr/bin, in an empty directory
  local d="$WORK/as-user" rc
  install -d -o gyro-station -g gyro-station "$d"
  local as=(runuser -u gyro-station -- env -i PATH=/usr/bin:/bin HOME="$d")
  (cd "$d" && "${as[@]}" simrig --gyros 2 --can-socket "$d/can.sock" >"$d/rig.toml" 2>"$d/simrig.log") &
  local rig=$!
  for _ in $(seq 50); do [[ -S $d/can.sock ]] && break; sleep 0.2; done
  (cd "$d" && "${as[@]}" station probe --config "$d/rig.toml") >"$WORK/probe.log" 2>&1
  rc=$?
  check '[[ $rc -eq 0 ]] && grep -q "SIM-0002" "$WORK/probe.log"' "installed station probe --config against simrig (exit $rc)"
  pkill -TERM -u gyro-station -f "simrig --gyros 2 --can-socket $d/can.sock"
  wait "$rig" 2>/dev/null
  (cd "$d" && "${as[@]}" station run --sim --new --db "$d/sim.db") >"$WORK/run.log" 2>&1
  rc=$?
  check '[[ $rc -eq 0 ]] && grep -q "(completed)" "$WORK/run.log"' "installed station run --sim (exit $rc)"
  [[ $FAILS -eq 0 ]] || tail -n 20 "$WORK/probe.log" "$WORK/run.log"
  rm -rf "$d"
}

start_systemd() {  # sets IN (how to reach a systemd); returns 1 (with a message) if none
  if [[ -d /run/systemd/system ]]; then IN=(); return 0; fi
  # Not PID 1 here (a container or a VM's init): boot one in its own PID and mount namespaces,
  # with its own /tmp and /run, up to sysinit.target only (no network or login units), /sys and
  # /proc/sys read-only so that its udev and sysctl units leave the machine's devices alone.
  unshare --pid --fork --mount --uts --propagation private --mount-proc sh -c '
    mount -t tmpfs -o mode=1777 tmpfs /tmp && mount -t tmpfs -o mode=0755 tmpfs /run &&
    install -d -m 1777 /run/lock && mount -o remount,bind,ro /sys &&
    mount --bind /proc/sys /proc/sys && mount -o remount,bind,ro /proc/sys &&
    exec env container=deb-test /lib/systemd/systemd --system --unit=sysinit.target' \
    >"$WORK/systemd.log" 2>&1 &
  local outer=$! st=""
  for _ in $(seq 50); do NS_PID=$(pgrep -P "$outer" | head -1) && [[ -n $NS_PID ]] && break; sleep 0.1; done
  [[ -n $NS_PID ]] || { echo "SKIP: no systemd (unshare failed: $(head -3 "$WORK/systemd.log"))"; return 1; }
  IN=(nsenter -t "$NS_PID" -m -p -u)
  for _ in $(seq 120); do
    st=$("${IN[@]}" systemctl is-system-running 2>/dev/null)
    [[ $st == running || $st == degraded ]] && break
    sleep 0.5
  done
  [[ $st == running || $st == degraded ]] || { echo "SKIP: the namespaced systemd did not come up ($st)"; return 1; }
  ok "systemd in its own namespaces ($st)"
}

api() { curl -s --max-time 5 "$@"; }
status_field() { api http://127.0.0.1:8080/api/status | python3 -c "import json,sys; s=json.load(sys.stdin); print(eval(sys.argv[1]))" "$1" 2>/dev/null; }
wait_until() {  # CONDITION SECONDS
  local end=$((SECONDS + $2))
  while ((SECONDS < end)); do eval "$1" && return 0; sleep 0.5; done
  return 1
}

config_error_logged() {  # (captured first: grep -q closing the pipe early fails under pipefail)
  local journal
  journal=$("${IN[@]}" journalctl --no-pager -u gyro-station)
  grep -q 'station: /etc/gyro-station/station.toml:[0-9]*:[0-9]*: TOML syntax' <<<"$journal"
}

next_version_deb() {  # the same package as version V+upgradetest1: a real upgrade for dpkg
  local d="$WORK/next" v
  v=$(dpkg-deb -f "$DEB" Version)
  rm -rf "$d" && dpkg-deb -R "$DEB" "$d"
  sed -i "s/^Version: .*/Version: ${v}+upgradetest1/" "$d/DEBIAN/control"
  dpkg-deb -b --root-owner-group "$d" "$WORK/gyro-station_${v}+upgradetest1.deb" >/dev/null
  echo "$WORK/gyro-station_${v}+upgradetest1.deb"
}

the_service() {
  "${IN[@]}" systemctl start gyro-station-simrig gyro-station
  check '"${IN[@]}" systemctl is-active --quiet gyro-station' "the hardened unit starts (Type=notify: READY)"
  local pid user
  pid=$("${IN[@]}" systemctl show -P MainPID gyro-station)
  user=$("${IN[@]}" ps -o user= -p "$pid" 2>/dev/null)
  check '[[ $user == gyro-station ]]' "it runs as gyro-station (pid $pid: $user)"
  check 'wait_until "[[ \$(status_field \"s[\\\"state\\\"]\") == idle ]]" 20' "GET /api/status: idle with the simulated rig read"
  local token run
  token=$(cat /var/lib/gyro-station/station.db.token)
  run=$(api -X POST -H "Authorization: Bearer $token" -H "Content-Type: application/json" \
    -d '{"protocol":"paper","operator":"deb-test"}' http://127.0.0.1:8080/api/runs |
    python3 -c "import json,sys; print(json.load(sys.stdin).get('run_id', 0))")
  check '[[ $run -gt 0 ]]' "a run started over the API: $run"
  wait_until '[[ $(status_field "s[\"ticks\"]") -ge 3 ]]' 20
  local next
  next=$(next_version_deb)
  "${IN[@]}" apt-get install -y "$next" >"$WORK/upgrade.log" 2>&1
  check '[[ $(dpkg-query -W -f="\${Version}" gyro-station) == *+upgradetest1 ]]' \
    "upgraded to $(dpkg-query -W -f='${Version}' gyro-station)"
  check 'grep -q "handing the running service over" "$WORK/upgrade.log"' "the upgrade hands the service over"
  check 'wait_until "[[ \$(\"\${IN[@]}\" systemctl show -P NRestarts gyro-station) -ge 1 ]] && \"\${IN[@]}\" systemctl is-active --quiet gyro-station" 30' \
    "systemd restarted it (exit 75, Restart=on-failure)"
  check 'wait_until "[[ \$(status_field \"s[\\\"run\\\"][\\\"id\\\"]\") == $run ]]" 30' "the new process resumed run $run"
  local kinds
  kinds=$(sqlite3 /var/lib/gyro-station/station.db "SELECT group_concat(kind) FROM events WHERE run_id = $run")
  check '[[ $kinds == *detach*resume* ]]' "the run's events: detach, then resume"
  "${IN[@]}" systemctl stop gyro-station gyro-station-simrig
  local state
  state=$(sqlite3 /var/lib/gyro-station/station.db "SELECT state FROM runs WHERE id = $run")
  check '[[ $state == stopped ]]' "systemctl stop: the run is closed 'stopped' ($state)"
  # A configuration error (exit 2) fails the unit once, with the reason in the journal; no loop
  # (a manual start resets NRestarts, so any restart in the 7 s would show as 1).
  cp /etc/gyro-station/station.toml "$WORK/station.toml.good"
  echo "garbage = [" >>/etc/gyro-station/station.toml
  "${IN[@]}" systemctl start gyro-station 2>/dev/null
  sleep 7
  check '"${IN[@]}" systemctl is-failed --quiet gyro-station && [[ $("${IN[@]}" systemctl show -P NRestarts gyro-station) -eq 0 ]]' \
    "a broken configuration: the unit fails once (RestartPreventExitStatus=2), no restart loop"
  check 'wait_until config_error_logged 10' "the journal names the file, line and column"
  cp "$WORK/station.toml.good" /etc/gyro-station/station.toml
  "${IN[@]}" systemctl reset-failed gyro-station
  [[ $FAILS -eq 0 ]] || "${IN[@]}" journalctl -u gyro-station --no-pager | tail -30
}

remove_and_purge_with_data() {
  "${IN[@]}" apt-get remove -y gyro-station >"$WORK/remove.log" 2>&1
  check '! [[ -e /usr/bin/station ]] && [[ -f /etc/gyro-station/station.toml ]]' "remove: binaries gone, conffile kept"
  "${IN[@]}" apt-get purge -y gyro-station >"$WORK/purge.log" 2>&1
  check '! [[ -e /etc/gyro-station ]]' "purge: /etc/gyro-station gone"
  check '[[ -f /var/lib/gyro-station/station.db ]] && getent passwd gyro-station >/dev/null' \
    "purge: the database and the user owning it are kept"
  check 'grep -q "holds data and is kept" "$WORK/purge.log"' "purge says so"
  echo "left after purge, with data: $(leftovers | tr '\n' ' ')"
  check '[[ $(leftovers | grep -v -e "^/var/lib/gyro-station$" -e "^passwd: " -e "^group: " | wc -l) -eq 0 ]]' \
    "nothing else is left"
  rm -rf /var/lib/gyro-station  # the README's "by hand, once the data is saved elsewhere"
  deluser --quiet --system gyro-station >/dev/null 2>&1
  delgroup --quiet --system gyro-station >/dev/null 2>&1
}

echo "== install, from the installed files only"
lintian_check
# The fleet's server is the user's: the package needs PostgreSQL's client library only.
DEPENDS=$(dpkg-deb -f "$DEB" Depends)
check '[[ $DEPENDS == *libpq5* && $DEPENDS != *postgresql* ]]' \
  "depends on libpq5, the PostgreSQL client library, and on no server: $DEPENDS"
install_checks
check 'systemd-analyze verify /usr/lib/systemd/system/gyro-station.service /usr/lib/systemd/system/gyro-station-simrig.service >"$WORK/verify.log" 2>&1 && ! [[ -s $WORK/verify.log ]]' \
  "systemd-analyze verify on the installed units: $(cat "$WORK/verify.log" 2>/dev/null)"
installed_files_only
echo "== the service under systemd"
if start_systemd; then HAVE_SYSTEMD=1; the_service; fi
echo "== remove and purge"
remove_and_purge_with_data
echo "== a second install, purged without data: nothing may be left"
"${IN[@]}" apt-get install -y "$DEB" >"$WORK/install2.log" 2>&1
if ((HAVE_SYSTEMD)); then  # installed with systemd running: enabled, known to it, not started
  check '[[ $("${IN[@]}" systemctl is-enabled gyro-station) == enabled ]] && ! "${IN[@]}" systemctl is-active --quiet gyro-station' \
    "installed under a running systemd: enabled ($("${IN[@]}" systemctl is-enabled gyro-station)), not started"
fi
"${IN[@]}" apt-get purge -y gyro-station >"$WORK/purge2.log" 2>&1
check '[[ -z $(leftovers) ]]' "purge without data leaves nothing: $(leftovers | tr '\n' ' ')"
if ((FAILS > 0)); then echo "deb_test: $FAILS failure(s); logs in $WORK"; exit 1; fi
rm -rf "$WORK"
echo "deb_test: ok"
