#!/bin/sh
# Builds and runs one libFuzzer target for a given time.
#   tests/fuzz/run.sh TARGET SECONDS [extra libFuzzer options...]
# TARGET is fuzz_<area>_<what>; its seeds are tests/fuzz/corpus/<area>/. New inputs go to a working corpus in
# the build directory (the repository's seeds are not modified); a crash is written to
# BUILD/fuzz-artifacts/TARGET/ and the script exits non-zero. The build directory is build-fuzz at the
# repository root unless AIRSEG_FUZZ_BUILD_DIR says otherwise; AIRSEG_FUZZ_PREBUILT=1 skips configuring and
# building (the target must be built there already). Needs clang (Debian: clang, libclang-rt-dev
# ships with it).
set -eu
if [ $# -lt 2 ]; then
    echo "usage: $0 TARGET SECONDS [libFuzzer options...]" >&2
    exit 2
fi
target=$1
seconds=$2
shift 2
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${AIRSEG_FUZZ_BUILD_DIR:-$root/build-fuzz}
area=$(echo "$target" | sed -n 's/^fuzz_\([a-z0-9]*\)_.*/\1/p')
if [ -z "$area" ]; then
    echo "$0: target names look like fuzz_<area>_<what>, got '$target'" >&2
    exit 2
fi

if [ "${AIRSEG_FUZZ_PREBUILT:-0}" = 1 ]; then
    # The caller built the targets already (CI's sanitize stage); several runs at once must not
    # regenerate the same build directory.
    [ -x "$build/tests/fuzz/$target" ] || { echo "$0: $build/tests/fuzz/$target is not built" >&2; exit 2; }
else
    # Tests stay configured (not built): the fuzz targets share the test tree's CMake files.
    CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DAIRSEG_BUILD_FUZZ=ON -DAIRSEG_BUILD_TESTS=ON \
        -DAIRSEG_SANITIZE=fuzzer-no-link,address,undefined >/dev/null
    cmake --build "$build" -j2 --target "$target"
fi

work="$build/fuzz-corpus/$target"
artifacts="$build/fuzz-artifacts/$target/"
mkdir -p "$work" "$artifacts"
seeds="$root/tests/fuzz/corpus/$area"
[ -d "$seeds" ] || seeds=""
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export ASAN_OPTIONS="detect_leaks=1"
# -rss_limit_mb: the machine is shared; -jobs/-workers stay at 1.
exec "$build/tests/fuzz/$target" -max_total_time="$seconds" -print_final_stats=1 -rss_limit_mb=1024 \
    -timeout=10 -artifact_prefix="$artifacts" "$@" "$work" $seeds
