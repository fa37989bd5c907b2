#!/usr/bin/env bash
# Builds everything and runs the whole test suite (ctest). Warnings are errors when CI=true.
#
# Then, for each architecture in AIRSEG_CROSS (default: none), cross-builds the package with its whole test
# suite and runs that suite under qemu-arm (packaging/ci-cross.sh; needs root on Debian 12), e.g.
# AIRSEG_CROSS="armhf armel" tools/build-and-test.sh. Not yet part of .ci/run: its time on a 2-core CI
# machine has not been measured end to end (docs/operations.md).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${AIRSEG_BUILD_DIR:-build}
cross=${AIRSEG_CROSS:-}
start=$SECONDS
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build" -G Ninja "${launcher[@]}"
cmake --build "$build" -j"$(nproc)"
# The MAVLink interoperability test needs node-mavlink (pinned by its lock file) in the build directory.
tests/integration/mavlink_interop/setup.sh "$build"
ctest --test-dir "$build" -j"$(nproc)" --output-on-failure --timeout 300
echo "build-and-test: native build and tests in $((SECONDS - start)) s"

if [ -n "$cross" ]; then
  # The ARM test suites run mavlink_interop too, with the node-mavlink set up above.
  # shellcheck disable=SC2086
  AIRSEG_INTEROP_MODULES="$(cd "$build" && pwd)/mavlink_interop/node_modules" packaging/ci-cross.sh $cross
fi
