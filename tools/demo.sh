#!/usr/bin/env bash
# tools/demo.sh [--resume] [--duration MS]
#
# The bench on one machine: airseg-linksim (a 57600-baud radio pair with a little loss, each radio on its
# host's USB through an FTDI-class adapter at its default 16-ms latency timer) between airsegd and the
# ground, the simulated autopilot when it is built (airseg-apmsim), airsegd on config/airseg.yaml, the
# ground station hub airseg-ground on the radio's ground end (with its live map in a browser), and airsegctl's
# live view through the hub in the foreground. Ctrl-C stops everything.
# Everything runs under build/demo/ (ptys, sockets, state, logs; AIRSEG_DEMO_DIR to put it elsewhere); no
# root is needed. Each run starts clean: a flight plan left by an earlier run is dropped unless --resume is
# given (airsegd would otherwise drive it again at once). --duration MS ends the demo by itself (for tests).
set -euo pipefail
cd "$(dirname "$0")/.."
resume=0
watch_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --resume) resume=1; shift ;;
    --duration) watch_args+=(--duration "${2:?--duration needs MS}"); shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "demo: unknown argument '$1'; see tools/demo.sh --help" >&2; exit 2 ;;
  esac
done
build=${AIRSEG_BUILD_DIR:-build}
run_dir=${AIRSEG_DEMO_DIR:-"$(pwd)/$build/demo"}
mkdir -p "$run_dir"
if [ "$resume" = 0 ]; then
  rm -rf "$run_dir/state"
fi
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
# HUP too: closing the terminal must not leave airsegd reopening ptys that other programs get next.
trap cleanup EXIT INT TERM HUP

wait_for() {  # wait_for PATH: until a pty link appears (at most 10 s)
  for _ in $(seq 100); do [ -e "$1" ] && return 0; sleep 0.1; done
  echo "demo: $1 did not appear" >&2; return 1
}

"$build/tools/linksim/airseg-linksim" --a "$run_dir/radio-air" --b "$run_dir/radio-ground" --baud 57600 \
  --usb-latency 16 --frame-loss 0.02 --seed 1 --control "$run_dir/linksim.ctl" > "$run_dir/linksim.log" 2>&1 &
pids+=($!)
wait_for "$run_dir/radio-air"

autopilot_port="$run_dir/apm"
if [ -x "$build/tools/apmsim/airseg-apmsim" ]; then
  "$build/tools/apmsim/airseg-apmsim" --link "$autopilot_port" > "$run_dir/apmsim.log" 2>&1 &
  pids+=($!)
  wait_for "$autopilot_port"
fi

# The ground link's key, made for this run as the package makes one at install: the vehicle and the hub
# hold the same one.
key="$run_dir/ground.key"
(umask 077 && od -An -N32 -tx1 /dev/urandom | tr -d ' \n' >"$key" && echo >>"$key")

"$build/daemon/airsegd" --config config/airseg.yaml \
  --set "status.socket=$run_dir/status.sock" --set "state_dir=$run_dir/state" \
  --set "autopilot.port=$autopilot_port" --set "groundlink.ports=[$run_dir/radio-air]" \
  --set "groundlink.key_file=$key" \
  --set groundlink.mavlink_forward.enabled=true \
  > "$run_dir/airsegd.log" 2>&1 &
pids+=($!)

# The map on a free port (named in the hub's log): a fixed one may be taken on a developer's machine.
"$build/ground/airseg-ground" --link "$run_dir/radio-ground" --baud 57600 --key "$key" --socket "$run_dir/ground.sock" \
  --map "127.0.0.1:${AIRSEG_DEMO_MAP_PORT:-0}" --map-control --mavlink-tcp "127.0.0.1:${AIRSEG_DEMO_MAVLINK_TCP:-0}" \
  --mavlink-udp "${AIRSEG_DEMO_MAVLINK_UDP:-127.0.0.1:14550}" \
  > "$run_dir/airseg-ground.log" 2>&1 &
pids+=($!)
wait_for "$run_dir/ground.sock"
map_url=""
for _ in $(seq 50); do
  map_url=$(sed -n 's/.*the map on \(http:[^ ]*\).*/\1/p' "$run_dir/airseg-ground.log")
  [ -n "$map_url" ] && break
  sleep 0.1
done

ctl="$build/client/airsegctl --ground-socket $run_dir/ground.sock"
# The hints stay under the live view (printed before it, the view's first refresh would clear them).
"$build/client/airsegctl" --ground-socket "$run_dir/ground.sock" --timeout 5000 watch "${watch_args[@]}" \
  --note "demo: logs in $run_dir; Ctrl-C stops it all" \
  --note "demo: the live map in a browser: ${map_url:-see $run_dir/airseg-ground.log}" \
  --note "demo: from another terminal: $ctl status" \
  --note "demo: a flight plan:        $ctl plan load config/plans/rover-survey.yaml"
