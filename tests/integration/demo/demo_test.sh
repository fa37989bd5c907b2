#!/usr/bin/env bash
# tools/demo.sh starts clean: a flight plan state left by an earlier run is dropped unless --resume is
# given, and the hint lines are part of the live view. Runs the demo for a bounded time (--duration) in a
# directory of its own.
set -euo pipefail
src=${1:?source dir} build=${2:?build dir}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
run_demo() {  # run_demo ARGS...: the demo's output in $dir/out; its exit code does not matter here
  # No MAVLink to UDP 14550: a test playing a ground station there may run at the same time.
  AIRSEG_BUILD_DIR=$build AIRSEG_DEMO_DIR=$dir AIRSEG_DEMO_MAVLINK_UDP=off \
    timeout 60 "$src/tools/demo.sh" --duration 1500 "$@" \
    >"$dir/out" 2>&1 </dev/null || true
}

mkdir -p "$dir/state"
echo stale >"$dir/state/left-by-an-earlier-run"
run_demo
if [ -e "$dir/state/left-by-an-earlier-run" ]; then
  echo "FAIL: the demo kept the state of an earlier run without --resume"; fail=1
else
  echo "ok: a plain run starts with no state of an earlier run"
fi

echo stale >"$dir/state/left-by-an-earlier-run"
run_demo --resume
if [ -e "$dir/state/left-by-an-earlier-run" ]; then
  echo "ok: --resume keeps the earlier state"
else
  echo "FAIL: --resume dropped the earlier state"; fail=1
fi

# The live view shows the hints on every refresh, once the radio link is up.
if grep -q "demo: a flight plan: .*plan load config/plans/rover-survey.yaml" "$dir/out"; then
  echo "ok: the hint lines are in the live view"
else
  echo "FAIL: no hint lines in the demo's output:"; cat "$dir/out"; fail=1
fi
if grep -q "demo: the live map in a browser: http://127.0.0.1:[0-9]*/" "$dir/out"; then
  echo "ok: the live view names the map's address"
else
  echo "FAIL: no map address in the demo's output:"; cat "$dir/out"; fail=1
fi
exit $fail
