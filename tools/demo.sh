#!/usr/bin/env bash
# Runs airsegd in the foreground on config/airseg.yaml, with its status socket and state in build/demo/ so no
# root is needed. In another terminal: build/client/airsegctl status --socket build/demo/status.sock
set -euo pipefail
cd "$(dirname "$0")/.."
build=${AIRSEG_BUILD_DIR:-build}
run_dir="$build/demo"
mkdir -p "$run_dir"
echo "demo: airsegd on config/airseg.yaml; status: $build/client/airsegctl status --socket $run_dir/status.sock"
exec "$build/daemon/airsegd" --config config/airseg.yaml \
  --set "status.socket=$run_dir/status.sock" --set "state_dir=$run_dir/state"
