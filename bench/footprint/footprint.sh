#!/usr/bin/env bash
# bench/footprint/footprint.sh [--build DIR] [--idle S] [--busy S] [--plan FILE] [--emulator armhf|armel]
#                              [--usb-latency MS] [--set KEY=VALUE]...   (passed to airsegd, e.g. threads=1)
#
# airsegd's memory and CPU on the bench wiring of tools/demo.sh, without the live view: airseg-linksim (a
# 57600-baud radio pair, 2 % frame loss, each radio on its host's USB through an FTDI-class adapter whose
# latency timer is --usb-latency, default 16 ms as FTDI ships it; 0 = bytes reach the host as they leave a
# bare UART), airseg-apmsim, airsegd on config/airseg.yaml, and a ground peer (airsegctl log over the radio,
# so the ground session is up and the 2 Hz vehicle telemetry flows).
# It measures in two phases:
#   idle  (--idle S, default 60): the link up, no plan; CPU seconds per minute.
#   busy  (--busy S, default 30): a plan running (--plan, default config/plans/rover-survey.yaml); CPU per
#         minute, then VmRSS, VmHWM (the peak), private memory (smaps Private_*), the heap's size ([heap]
#         mapping: malloc's high-water mark unless it trimmed the top) and the program's own mapped code.
# --emulator ARCH runs airsegd from an ARM cross build (--build, e.g. build-pkg-cross-armhf) under
# qemu-ARCH-static with QEMU_LD_PREFIX=sysroots/ARCH, the simulators from the native build (AIRSEG_BUILD_DIR,
# default build). Under qemu-user the host process also holds qemu's own memory and translated code, so the
# figures are those of the guest's address space: the host mappings inside the range qemu reserves for it
# (guest_base is fixed with QEMU_GUEST_BASE to find it). CPU under emulation is not meaningful and is not
# printed.
# Everything runs in a temporary directory; nothing needs root. The run takes about idle+busy+10 s.
set -euo pipefail
cd "$(dirname "$0")/../.."
native=${AIRSEG_BUILD_DIR:-build}
build=""
idle_s=60
busy_s=30
plan=config/plans/rover-survey.yaml
emulator=""
usb_latency=16
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=${2:?--build needs DIR}; shift 2 ;;
    --idle) idle_s=${2:?--idle needs seconds}; shift 2 ;;
    --busy) busy_s=${2:?--busy needs seconds}; shift 2 ;;
    --plan) plan=${2:?--plan needs FILE}; shift 2 ;;
    --emulator) emulator=${2:?--emulator needs armhf or armel}; shift 2 ;;
    --usb-latency) usb_latency=${2:?--usb-latency needs milliseconds}; shift 2 ;;
    --set) extra+=(--set "${2:?--set needs KEY=VALUE}"); shift 2 ;;
    -h|--help) sed -n '2,21p' "$0"; exit 0 ;;
    *) echo "footprint: unknown argument '$1'; see $0 --help" >&2; exit 2 ;;
  esac
done
build=${build:-$native}
daemon="$build/daemon/airsegd"
for program in "$daemon" "$native/tools/linksim/airseg-linksim" "$native/tools/apmsim/airseg-apmsim" \
    "$native/client/airsegctl"; do
  [ -x "$program" ] || { echo "footprint: $program is not built" >&2; exit 2; }
done
guest_base=0x40000000
# AIRSEG_FOOTPRINT_WRAP: a command put before airsegd, e.g. "valgrind --tool=callgrind" to see where its
# time goes (the figures printed are then those of the wrapped process).
read -r -a launch <<<"${AIRSEG_FOOTPRINT_WRAP:-}"
if [ -n "$emulator" ]; then
  case "$emulator" in
    armhf|armel) ;;
    *) echo "footprint: --emulator takes armhf or armel, not '$emulator'" >&2; exit 2 ;;
  esac
  sysroot=${AIRSEG_SYSROOTS:-sysroots}/$emulator
  [ -d "$sysroot" ] || { echo "footprint: no sysroot at $sysroot (packaging/ensure-sysroot.sh $emulator $sysroot)" >&2; exit 2; }
  command -v qemu-arm-static >/dev/null || { echo "footprint: qemu-arm-static is not installed" >&2; exit 2; }
  launch=(env QEMU_LD_PREFIX="$sysroot" QEMU_GUEST_BASE=$guest_base qemu-arm-static)
fi

run_dir=$(mktemp -d /tmp/airseg-footprint.XXXXXX)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  [ -n "${AIRSEG_FOOTPRINT_KEEP:-}" ] || rm -rf "$run_dir"
}
trap cleanup EXIT INT TERM HUP

wait_for() {  # wait_for PATH: until a pty link appears (at most 10 s)
  for _ in $(seq 100); do [ -e "$1" ] && return 0; sleep 0.1; done
  echo "footprint: $1 did not appear" >&2; return 1
}

"$native/tools/linksim/airseg-linksim" --a "$run_dir/radio-air" --b "$run_dir/radio-ground" --baud 57600 \
  --usb-latency "$usb_latency" --frame-loss 0.02 --seed 1 > "$run_dir/linksim.log" 2>&1 &
pids+=($!)
wait_for "$run_dir/radio-air"
"$native/tools/apmsim/airseg-apmsim" --link "$run_dir/apm" > "$run_dir/apmsim.log" 2>&1 &
pids+=($!)
wait_for "$run_dir/apm"
"${launch[@]}" "$daemon" --config config/airseg.yaml \
  --set "status.socket=$run_dir/status.sock" --set "state_dir=$run_dir/state" \
  --set "autopilot.port=$run_dir/apm" --set "groundlink.ports=[$run_dir/radio-air]" \
  --set groundlink.key_file= --set groundlink.insecure=true "${extra[@]}" \
  > "$run_dir/airsegd.log" 2>&1 &
daemon_pid=$!
pids+=($daemon_pid)
"$native/client/airsegctl" --link "$run_dir/radio-ground" --baud 57600 log --duration $(((idle_s + busy_s + 60) * 1000)) \
  > "$run_dir/ground.log" 2>&1 &
pids+=($!)

ctl=("$native/client/airsegctl" --socket "$run_dir/status.sock" --timeout 20000)
# Ready: the autopilot connected and the ground session up, as the status document says.
for _ in $(seq 60); do
  if status=$("${ctl[@]}" --json status 2>/dev/null) &&
      python3 -c 'import json,sys; s=json.load(sys.stdin); sys.exit(0 if s["autopilot"].get("ready") and s["groundlink"].get("link")=="up" else 1)' <<<"$status" 2>/dev/null; then
    break
  fi
  sleep 0.1
done
"${ctl[@]}" --json status > "$run_dir/status.json" 2>/dev/null || { echo "footprint: airsegd did not answer" >&2; cat "$run_dir/airsegd.log" >&2; exit 1; }

# CPU time in ns over all of airsegd's threads (schedstat: finer than the 10 ms ticks of /proc/PID/stat).
cpu_ns() { cat /proc/"$daemon_pid"/task/*/schedstat | awk '{ sum += $1 } END { printf "%.0f", sum }'; }
# Times airsegd's threads went to sleep (voluntary context switches): each is one wake-up later. On an idle
# daemon the wake-ups, not the instructions run in them, are most of the CPU time, and unlike the CPU time
# their count does not depend on the machine or on what else it runs.
sleeps() { cat /proc/"$daemon_pid"/task/*/status | awk '$1 == "voluntary_ctxt_switches:" { sum += $2 } END { print sum + 0 }'; }
cpu_per_minute() {  # cpu_per_minute SECONDS: airsegd's CPU seconds per minute, and wake-ups per second
  local before after slept_before slept_after
  before=$(cpu_ns)
  slept_before=$(sleeps)
  sleep "$1"
  after=$(cpu_ns)
  slept_after=$(sleeps)
  awk -v d=$((after - before)) -v w=$((slept_after - slept_before)) -v s="$1" \
    'BEGIN { printf "%.3f s per minute, %.1f wake-ups per second", d / 1e9 * 60 / s, w / s }'
}

kib_of() { awk -v k="$1:" '$1 == k { print $2 }' "/proc/$daemon_pid/status"; }
# Sums a smaps field over the mappings inside [lo, hi) (all mappings when hi is 0).
smaps_sum() {
  awk -v field="$1:" -v lo="$2" -v hi="$3" '
    function hex(s,   i, c, v) { v = 0; s = tolower(s)
      for (i = 1; i <= length(s); i++) { c = index("0123456789abcdef", substr(s, i, 1)) - 1; v = v * 16 + c }
      return v }
    /^[0-9a-f]+-[0-9a-f]+ / { split($1, r, "-"); start = hex(r[1]); inside = (hi == 0) || (start >= lo && start < hi)
      name = $6; next }
    $1 == field && inside { sum += $2 }
    END { print sum + 0 }' "/proc/$daemon_pid/smaps"
}
own_code_kib() {  # the daemon binary's own mapped text (under qemu-user its guest pages are not executable)
  awk -v bin="$(readlink -f "$daemon")" -v perms="${emulator:+.}" '
    /^[0-9a-f]+-[0-9a-f]+ / { mine = ($6 == bin) && ($2 ~ (perms == "" ? "x" : perms)); next }
    $1 == "Rss:" && mine { sum += $2 }
    END { print sum + 0 }' "/proc/$daemon_pid/smaps"
}
heap_kib() { awk '/\[heap\]/ { h = 1; next } /^[0-9a-f]+-[0-9a-f]+ / { h = 0 } h && $1 == "Size:" { print $2 }' \
  "/proc/$daemon_pid/smaps"; }

echo "footprint: airsegd (pid $daemon_pid) $(readlink -f "$daemon")${emulator:+ under qemu-arm-static ($emulator)}"
if [ -z "$emulator" ]; then
  echo "idle (link up, no plan, 2 Hz telemetry, radio adapters' latency timer ${usb_latency} ms), ${idle_s} s: CPU $(cpu_per_minute "$idle_s")"
else
  sleep "$idle_s"
fi
"${ctl[@]}" plan load "$plan" > "$run_dir/plan.log" 2>&1 || { echo "footprint: plan load failed:" >&2; cat "$run_dir/plan.log" >&2; exit 1; }
if [ -z "$emulator" ]; then
  echo "busy (plan $plan running), ${busy_s} s: CPU $(cpu_per_minute "$busy_s")"
  echo "VmRSS $(kib_of VmRSS) KiB, VmHWM $(kib_of VmHWM) KiB, private $(( $(smaps_sum Private_Clean 0 0) + $(smaps_sum Private_Dirty 0 0) )) KiB, heap (brk; its high-water mark unless trimmed) $(heap_kib) KiB, own code $(own_code_kib) KiB"
else
  sleep "$busy_s"
  lo=$((guest_base)); hi=$((guest_base + 0x100000000))
  rss=$(smaps_sum Rss "$lo" "$hi")
  private=$(( $(smaps_sum Private_Clean "$lo" "$hi") + $(smaps_sum Private_Dirty "$lo" "$hi") ))
  echo "guest address space (the ARM program's own memory): RSS $rss KiB, private $private KiB, own code $(own_code_kib) KiB"
  echo "host process (qemu included): VmRSS $(kib_of VmRSS) KiB"
fi
