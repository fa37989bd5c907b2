#!/bin/bash
# cross-test.sh ARCH [CTEST_ARGS...]
#
# Cross-builds the whole test suite for ARCH (armhf, armel, arm64) with packaging/toolchain-ARCH.cmake
# against sysroots/ARCH, and runs it with ctest under qemu-arm-static (arm64: qemu-aarch64-static)
# -L SYSROOT (the toolchain file's CMAKE_CROSSCOMPILING_EMULATOR, which gtest_discover_tests also uses
# to list the cases). Tests that spawn helper programs (simulators) start ARM binaries: binfmt_misc
# hands those to qemu, and QEMU_LD_PREFIX (set here) points it at the sysroot.
#
# Build directory: build-pkg-cross-ARCH (AIRSEG_BUILD_DIR to change). AIRSEG_SOURCE_DIR builds
# another source tree (default: this one). AIRSEG_TARGETS="a b" builds only those targets (then
# pick their tests with ctest -R / -L). Extra arguments go to ctest.
set -euo pipefail
. "$(dirname "$0")/lib.sh"

[ $# -ge 1 ] || die "usage: $0 ARCH [CTEST_ARGS...]"
arch=$1; shift
case "$arch" in armhf|armel|arm64) ;; *) die "cross-test.sh runs armhf, armel or arm64, not '$arch'" ;; esac
src=${AIRSEG_SOURCE_DIR:-$AIRSEG_ROOT}
build=${AIRSEG_BUILD_DIR:-$AIRSEG_ROOT/build-pkg-cross-$arch}
sysroot=$AIRSEG_SYSROOTS/$arch
jobs=${AIRSEG_JOBS:-2}

# shellcheck disable=SC2046
ensure_packages cmake ninja-build pkgconf ccache $(cross_tools "$arch")
"$AIRSEG_ROOT/packaging/ensure-sysroot.sh" "$arch" "$sysroot"
if enable_arm_binfmt "$arch"; then
  log "binfmt_misc runs $arch programs through $(qemu_for "$arch")"
else
  log "warning: binfmt_misc is not available: only test binaries run (through the emulator);" \
      "a test that spawns an ARM helper program fails"
fi

start=$SECONDS
mkdir -p "$build"
# shellcheck disable=SC2046
cmake -S "$src" -B "$build" -G Ninja \
  -DCMAKE_TOOLCHAIN_FILE="$AIRSEG_ROOT/packaging/toolchain-$arch.cmake" -DAIRSEG_SYSROOT="$sysroot" \
  -DAIRSEG_BUILD_FUZZ=OFF -DAIRSEG_WERROR=ON $(ccache_launcher_args) >"$build/configure.log" \
  || { cat "$build/configure.log"; die "configure failed"; }
# shellcheck disable=SC2086
cmake --build "$build" -j "$jobs" ${AIRSEG_TARGETS:+--target $AIRSEG_TARGETS}
built=$SECONDS
export QEMU_LD_PREFIX=$sysroot
ctest --test-dir "$build" --output-on-failure --parallel "$jobs" "$@"
log "$arch: build $((built - start)) s, tests $((SECONDS - built)) s"
