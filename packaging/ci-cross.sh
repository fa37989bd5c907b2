#!/bin/bash
# ci-cross.sh [--prepare] [ARCH...]
#
# The package stage of CI, on a fresh Debian 12 amd64 machine (as root). ARCH: amd64, armhf, armel,
# arm64 (default: all four).
#
# 1. Installs the tools it needs with apt-get, lets binfmt_misc run ARM programs through
#    qemu-arm, and builds the sysroots.
# 2. Builds each ARM package; each armhf and armel package build compiles the whole test suite with -Werror and
#    runs it under qemu-arm (arm64's only with AIRSEG_CROSS_TEST_ARM64=1) (ctest through the toolchain file's emulator, helper programs through
#    binfmt_misc), so the ARM binaries are tested as they are packaged, with two differences: no
#    debug information (-g0, no -dbgsym package: a quarter less compile time, the same machine
#    code), and the test-only hang injection compiled in (the stuck-service test runs on ARM too).
# 3. Checks each .deb (packaging/check-deb.sh: lintian, Architecture, shlibs Depends, ELF format
#    and loader).
# 4. amd64 is built first, without its tests (the whole suite runs natively in CI's sanitize stage) and
#    without debug information, checked the same way (with the manual pages against --help), rebuilt from
#    the same build directory as the next version (build-debs.sh --upgrade-build), and then installed,
#    upgraded to that rebuild and removed in a throwaway chroot (packaging/test-install.sh) in the background
#    while the ARM packages build: that test mostly downloads. AIRSEG_CI_SKIP_INSTALL_TEST=1 skips it.
# With --prepare, only step 1: CI runs it in the background while it compiles the sanitizer build, so
# the downloads overlap the compiling.
# The .debs are left in dist/. Each step prints its start time in seconds since the stage began,
# and the stage ends with one line per architecture: build and test wall time, CPU time, and the
# ctest summary.
set -euo pipefail
. "$(dirname "$0")/lib.sh"

prepare_only=0
arches=()
for a in "$@"; do
  case "$a" in
    --prepare) prepare_only=1 ;;
    amd64|armhf|armel|arm64) arches+=("$a") ;;
    -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
    *) die "unknown argument '$a' (expected --prepare, amd64, armhf, armel, arm64)" ;;
  esac
done
[ ${#arches[@]} -gt 0 ] || arches=(amd64 armhf armel arm64)

t0=$SECONDS
step() { log "[$((SECONDS - t0)) s] $*"; }
# User + system CPU seconds of this script's finished children so far (read from /proc: `times` in a
# command substitution would report the subshell's own children).
cpu_seconds() {
  local f
  read -r -a f <"/proc/$$/stat"
  echo $(((f[15] + f[16]) / $(getconf CLK_TCK)))
}

step "installing build tools"
cross=()
for arch in "${arches[@]}"; do
  # shellcheck disable=SC2207
  cross+=($(cross_tools "$arch"))
done
ensure_packages "${AIRSEG_NATIVE_TOOLS[@]}" ccache "${AIRSEG_DEV_PACKAGES[@]}" "${cross[@]}"
for arch in "${arches[@]}"; do
  [ "$arch" != amd64 ] || continue
  if enable_arm_binfmt "$arch"; then
    step "binfmt_misc runs $arch programs through $(qemu_for "$arch")"
  else
    die "binfmt_misc cannot run $arch programs through $(qemu_for "$arch") here (needs root and the" \
        "binfmt_misc file system); the tests that start the simulators would fail"
  fi
done
for arch in "${arches[@]}"; do
  [ "$arch" != amd64 ] || continue
  step "sysroot $arch"
  "$AIRSEG_ROOT/packaging/ensure-sysroot.sh" "$arch" "$AIRSEG_SYSROOTS/$arch"
done
if [ "$prepare_only" = 1 ]; then
  step "prepared"
  exit 0
fi

summary=()
install_pid=""
mkdir -p "$AIRSEG_ROOT/build-logs"
for arch in "${arches[@]}"; do
  start=$SECONDS cpu0=$(cpu_seconds)
  if [ "$arch" = amd64 ]; then
    step "building amd64 (its tests run in the sanitize stage)"
    "$AIRSEG_ROOT/packaging/build-debs.sh" --no-check --no-debug-info amd64
    summary+=("amd64: $((SECONDS - start)) s wall, $(($(cpu_seconds) - cpu0)) CPU-s; packages checked")
    if [ "${AIRSEG_CI_SKIP_INSTALL_TEST:-0}" != 1 ]; then
      step "the amd64 packages rebuilt as the next version, for the upgrade"
      "$AIRSEG_ROOT/packaging/build-debs.sh" --no-check --no-debug-info --upgrade-build amd64
      summary+=("amd64 rebuilt as the next version: $((SECONDS - start)) s wall since the amd64 build began")
      step "install / upgrade / remove test of the amd64 packages, in the background"
      # Its own copy: the ARM builds write dist/ meanwhile.
      rm -rf "$AIRSEG_ROOT/build-logs/install-debs" && mkdir -p "$AIRSEG_ROOT/build-logs/install-debs/next"
      cp "$AIRSEG_ROOT"/dist/*_amd64.deb "$AIRSEG_ROOT"/dist/*_all.deb "$AIRSEG_ROOT/build-logs/install-debs/"
      cp "$AIRSEG_ROOT"/dist/upgrade-test/*.deb "$AIRSEG_ROOT/build-logs/install-debs/next/"
      "$AIRSEG_ROOT/packaging/test-install.sh" "$AIRSEG_ROOT/build-logs/install-debs" \
        "$AIRSEG_ROOT/build-logs/install-debs/next" >"$AIRSEG_ROOT/build-logs/test-install.log" 2>&1 &
      install_pid=$!
    fi
    continue
  fi
  if [ "$arch" = arm64 ] && [ "${AIRSEG_CROSS_TEST_ARM64:-0}" != 1 ]; then
    # A 64-bit little-endian target like amd64, whose suite runs under the sanitizers: what differs on ARM
    # (32-bit sizes and alignment, armel's soft float and atomics, qemu's timing) is tested on armhf and
    # armel. Its packages are built with -Werror and checked; AIRSEG_CROSS_TEST_ARM64=1 runs its suite too.
    step "cross-building arm64 without its test suite (AIRSEG_CROSS_TEST_ARM64=1 runs it under qemu-aarch64)"
    "$AIRSEG_ROOT/packaging/build-debs.sh" --no-check --no-debug-info "$arch"
    summary+=("$arch: $((SECONDS - start)) s wall, $(($(cpu_seconds) - cpu0)) CPU-s; packages checked, suite not run")
    continue
  fi
  step "cross-building $arch and running its test suite under $(qemu_for "$arch")"
  AIRSEG_EXTRA_CMAKE_ARGS="-DAIRSEG_TEST_HANG_INJECTION=ON" \
    "$AIRSEG_ROOT/packaging/build-debs.sh" --no-debug-info "$arch"
  tests=$(grep -E '^[0-9]+% tests passed' "$AIRSEG_ROOT/build-pkg-$arch/build.log" | tail -n1)
  summary+=("$arch: $((SECONDS - start)) s wall, $(($(cpu_seconds) - cpu0)) CPU-s; ${tests:-no ctest summary}")
done
if [ -n "$install_pid" ]; then
  step "waiting for the install test"
  if wait "$install_pid"; then
    cat "$AIRSEG_ROOT/build-logs/test-install.log"
  else
    cat "$AIRSEG_ROOT/build-logs/test-install.log"
    die "the install / upgrade / remove test failed"
  fi
fi

for deb in "$AIRSEG_ROOT"/dist/*.deb; do
  echo "== $(basename "$deb")"
  dpkg-deb --info "$deb" | sed -n '/^ Package:/,$p'
done
step "done"
printf 'ci-cross: %s\n' "${summary[@]}"
