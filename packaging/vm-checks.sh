#!/bin/bash
# Runs inside the virtual machine of packaging/test-vm.sh, started at boot by airseg-vm-checks.service once
# airsegd has started: checks the installed packages under the real systemd and prints each check with its
# evidence, one line each ("ok: ..." or "FAIL: ..."), then "vm-checks: done, N failed" and powers off.
# NEXT is the version the upgrade goes to; /root/debs/next holds its packages.
set -u
next=$(cat /root/debs/next-version)
fail=0
ok() { echo "ok: $*"; }
bad() {
  echo "FAIL: $*"
  fail=$((fail + 1))
}
prop() { systemctl show -p "$1" --value airsegd.service; }
# wait_for SECONDS COMMAND...: true once COMMAND succeeds, polled every 0.2 s.
wait_for() {
  local deadline=$((SECONDS + $1))
  shift
  until "$@" >/dev/null 2>&1; do
    [ "$SECONDS" -lt "$deadline" ] || return 1
    sleep 0.2
  done
}
active() { [ "$(systemctl is-active airsegd.service)" = active ]; }
autopilot_up() { prop StatusText | grep -q 'autopilot: UP'; }
pid_changed_from() { [ "$(prop MainPID)" != "$1" ] && [ "$(prop MainPID)" != 0 ] && active; }
journal() { journalctl -u airsegd.service -o cat --no-pager "$@"; }

echo "vm-checks: $(uname -r), $(systemctl --version | head -n1), airsegd $(dpkg-query -W -f '${Version}' airsegd)"

wait_for 60 active && ok "started at boot: $(systemctl is-enabled airsegd.service), $(prop ActiveState)/$(prop SubState)," \
  "MainPID $(prop MainPID), since $(prop ActiveEnterTimestamp)" || bad "airsegd not active: $(prop ActiveState)/$(prop SubState)"
# A Type=notify service is active only after READY=1.
[ "$(prop Type)" = notify ] && active && ok "READY=1 received (Type=notify, active)" || bad "no READY: Type $(prop Type)"
[ -n "$(prop StatusText)" ] && ok "STATUS=$(prop StatusText)" || bad "no STATUS= line"
if wait_for 120 autopilot_up; then
  ok "the autopilot is ready through the hardened unit on /dev/ttyS1 (DevicePolicy=$(prop DevicePolicy)," \
    "User=$(prop User)): STATUS=$(prop StatusText)"
else
  bad "the autopilot is not ready: STATUS=$(prop StatusText); $(journal -n 5 | tr '\n' '|')"
fi

key=/etc/airseg/ground.key
[ "$(stat -c '%a %U' "$key" 2>&1)" = "600 airseg" ] && ok "the ground-link key made at install: $key, mode 600, owner airseg" \
  || bad "the key: $(stat -c '%a %U' "$key" 2>&1)"
key_sum=$(sha256sum "$key")
ctl=(airsegctl --udp 127.0.0.1:14650 --timeout 30000)
out=$("${ctl[@]}" status 2>&1 >/dev/null)
code=$?
[ "$code" = 3 ] && grep -q 'not authorised' <<<"$out" && ok "airsegctl without the key: exit $code, \"$out\"" \
  || bad "airsegctl without the key: exit $code, \"$out\""
out=$("${ctl[@]}" --key "$key" rates vehicle=2 2>&1)
code=$?
[ "$code" = 0 ] && ok "airsegctl with the key commands: rates vehicle=2, exit 0" || bad "with the key: exit $code, $out"

pid=$(prop MainPID)
restarts=$(prop NRestarts)
kill -STOP "$pid"
stopped_at=$SECONDS
if wait_for 60 pid_changed_from "$pid"; then
  ok "watchdog: PID $pid stopped, restarted as PID $(prop MainPID) after $((SECONDS - stopped_at)) s," \
    "NRestarts $restarts -> $(prop NRestarts); journal: \"$(journal | grep -m1 'Watchdog timeout')\""
else
  bad "no restart after SIGSTOP: $(prop ActiveState), NRestarts $(prop NRestarts)"
fi
wait_for 60 active

pid=$(prop MainPID)
since=$(journal | wc -l)
systemctl reload airsegd.service
if wait_for 20 sh -c "journalctl -u airsegd.service -o cat --no-pager | tail -n +$((since + 1)) | grep -q 'config: reloaded'"; then
  ok "SIGHUP (systemctl reload): same PID $(prop MainPID); journal: \"$(journal | tail -n +$((since + 1)) | grep -m1 'config: reloaded')\""
else
  bad "no reload line after systemctl reload"
fi
[ "$(prop MainPID)" = "$pid" ] || bad "the reload changed the PID"

pid=$(prop MainPID)
dpkg -i /root/debs/next/*.deb </dev/null >/tmp/upgrade.log 2>&1 || bad "the upgrade failed: $(tail -n 5 /tmp/upgrade.log | tr '\n' '|')"
version=$(dpkg-query -W -f '${Version}' airsegd)
if [ "$version" = "$next" ] && wait_for 60 pid_changed_from "$pid"; then
  ok "upgrade to $version restarted the daemon: PID $pid -> $(prop MainPID)"
else
  bad "upgrade: version $version, PID $pid -> $(prop MainPID), $(prop ActiveState)"
fi
grep -q '/dev/ttyS1' /etc/airseg/conf.d/50-vm.yaml && ok "the conf.d drop-in is kept" || bad "the drop-in is gone"
[ "$(sha256sum "$key")" = "$key_sum" ] && ok "the upgrade kept the ground-link key" || bad "the upgrade changed the key"
wait_for 120 autopilot_up && ok "after the upgrade, through the drop-in's port: STATUS=$(prop StatusText)" \
  || bad "after the upgrade: STATUS=$(prop StatusText)"

limit=$(prop TimeoutStopUSec)
started=$(date +%s%N)
systemctl stop airsegd.service
took_ms=$((($(date +%s%N) - started) / 1000000))
if [ "$(prop Result)" = success ] && [ "$took_ms" -lt 20000 ]; then
  ok "stopped in $took_ms ms (TimeoutStopSec $limit), Result=success, exit status $(prop ExecMainStatus)"
else
  bad "stop: $took_ms ms, Result=$(prop Result), exit status $(prop ExecMainStatus)"
fi

lines=$(journal | wc -l)
[ "$lines" -gt 0 ] && ok "journal: $lines lines of airsegd.service, the first: \"$(journal | head -n1)\"" \
  || bad "nothing in the journal"
journal | grep -E 'groundlink: (link up|refused)|autopilot.*(READY|ready)' | head -n 4 | sed 's/^/  journal: /'
echo "ok: exposure: $(systemd-analyze security --no-pager airsegd.service | tail -n1)"
echo "vm-checks: boot: $(systemd-analyze time 2>/dev/null | head -n1)"
echo "vm-checks: done, $fail failed"
systemctl poweroff --no-block
