#!/usr/bin/env bash
# The bench on one machine: airseg-linksim (a 57600-baud radio pair with a little loss) between airsegd and
# the ground, the simulated autopilot when it is built (airseg-apmsim), airsegd on config/airseg.yaml, and
# airsegctl's live view over the radio in the foreground. Ctrl-C stops everything.
# Everything runs under build/demo/ (ptys, sockets, state, logs); no root is needed.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${AIRSEG_BUILD_DIR:-build}
run_dir="$(pwd)/$build/demo"
mkdir -p "$run_dir"
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
  --frame-loss 0.02 --seed 1 --control "$run_dir/linksim.ctl" > "$run_dir/linksim.log" 2>&1 &
pids+=($!)
wait_for "$run_dir/radio-air"

autopilot_port="$run_dir/apm"
if [ -x "$build/tools/apmsim/airseg-apmsim" ]; then
  "$build/tools/apmsim/airseg-apmsim" --link "$autopilot_port" > "$run_dir/apmsim.log" 2>&1 &
  pids+=($!)
  wait_for "$autopilot_port"
fi

"$build/daemon/airsegd" --config config/airseg.yaml \
  --set "status.socket=$run_dir/status.sock" --set "state_dir=$run_dir/state" \
  --set "autopilot.port=$autopilot_port" --set "groundlink.ports=[$run_dir/radio-air]" \
  > "$run_dir/airsegd.log" 2>&1 &
pids+=($!)

echo "demo: logs in $run_dir; on-board status: $build/client/airsegctl --local --socket $run_dir/status.sock status"
echo "demo: a flight plan: $build/client/airsegctl --local --socket $run_dir/status.sock plan load config/plans/rover-survey.yaml"
"$build/client/airsegctl" --link "$run_dir/radio-ground" --baud 57600 --timeout 5000 watch
