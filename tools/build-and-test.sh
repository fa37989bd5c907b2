#!/usr/bin/env bash
# Builds everything and runs the whole test suite (ctest). Warnings are errors when CI=true.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${AIRSEG_BUILD_DIR:-build}
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build" -G Ninja "${launcher[@]}"
cmake --build "$build" -j"$(nproc)"
# The MAVLink interoperability test needs node-mavlink (pinned by its lock file) in the build directory.
tests/integration/mavlink_interop/setup.sh "$build"
ctest --test-dir "$build" -j"$(nproc)" --output-on-failure --timeout 300
