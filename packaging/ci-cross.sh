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
# 4. amd64 is built without its tests (the whole suite runs natively in CI's sanitize stage) and without
#    debug information, checked the same way (with the manual pages against --help), rebuilt from the same
#    build directory as the next version (build-debs.sh --upgrade-build), and then installed, upgraded to
#    that rebuild and removed in a throwaway chroot (packaging/test-install.sh); all of it at the lowest
#    priority beside the ARM builds, whose suites leave a core mostly idle (AIRSEG_CROSS_OVERLAP=0: first,
#    before them); then booted under a real systemd in a virtual machine (packaging/test-vm.sh).
#    AIRSEG_CI_SKIP_INSTALL_TEST=1 skips both.
# AIRSEG_CROSS_SUITE_DONE=FILE: CI started this stage beside another suite (at nice 14), which has ended when
# FILE exists. Meanwhile the ARM builds are 3 apart (armel at the stage's priority, armhf 3 below, arm64 at 19;
# amd64 at 19 throughout); then they move up, still below any suite's priority (nice 10, 15, 19: a suite is
# always running from then on), and the install and boot tests start.
# The ARM builds start in the order of their suites' length, longest first: armel, armhf, arm64.
# The builds no suite waits for (the arm64 packages, the amd64 packages and their rebuild) compile at SCHED_IDLE
# (AIRSEG_CROSS_IDLE=0: at nice 19 only): they take only the CPU that nothing else wants, which is the end of the
# run, where the last suite's simulated-rover chains leave most of the machine idle. They come one after the
# other, amd64 first: its install test and the virtual machine's boot then run beside arm64's compile and the
# last suite, not after everything else with half the machine idle.
# The suites take AIRSEG_TEST_LOCK (default: one of this stage's own): one suite's CPU-bound part at a time,
# their simulated-rover chains side by side (tools/run-ctest.sh).
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
    -h|--help) sed -n '2,/^set -euo/{/^#/p}' "$0"; exit 0 ;;
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
version=$(dpkg-parsechangelog -l "$AIRSEG_ROOT/packaging/debian/changelog" -S Version)
mkdir -p "$AIRSEG_CI_LOGS"
rm -f "$AIRSEG_CI_LOGS/cross-amd64.summary"
# The ARM builds that run a suite under qemu, and those that are only built and checked.
arm_with_suite() { [ "$1" != arm64 ] || [ "${AIRSEG_CROSS_TEST_ARM64:-0}" = 1 ]; }
# at_idle_priority CMD...: CMD at SCHED_IDLE (AIRSEG_CROSS_IDLE=1, the default), for work no suite waits for.
at_idle_priority() {
  if [ "${AIRSEG_CROSS_IDLE:-1}" = 1 ]; then chrt --idle 0 "$@"; else "$@"; fi
}
# build_arm ARCH: one ARM package build (with its suite where arm_with_suite), its compiles counted apart.
build_arm() {
  local arch=$1
  ccache_stage_begin "cross-$arch"
  # The benchmarks are compiled on armhf (GCC's 32-bit ARM warnings on their code too), not again on armel:
  # nothing runs them under qemu, and the sanitize stage compiles them as well.
  local bench=""
  [ "$arch" = armhf ] || bench="-DAIRSEG_BUILD_BENCH=OFF"
  # The test sources at -O1 (AIRSEG_TEST_OPTIMIZATION): 20-40 % less compile time for two thirds of the
  # build; the libraries and programs they test stay as packaged (-O2). Each test executable one translation
  # unit (AIRSEG_TEST_UNITY_BATCH_SIZE=0): its headers parsed and templates instantiated once.
  if arm_with_suite "$arch"; then
    AIRSEG_EXTRA_CMAKE_ARGS="-DAIRSEG_TEST_HANG_INJECTION=ON -DAIRSEG_TEST_OPTIMIZATION=-O1 -DAIRSEG_TEST_UNITY_BATCH_SIZE=0${bench:+ $bench}" \
      "$AIRSEG_ROOT/packaging/build-debs.sh" --no-debug-info "$arch"
  else
    # The two builds nothing waits for come one after the other, amd64's first: its install test and the
    # virtual machine's boot (a core for two minutes, then half the machine idle) follow it, and run beside
    # this build and the last suite instead of after everything else.
    if [ -n "$amd64_built" ]; then
      step "$arch waits for the amd64 packages ($amd64_built)"
      while [ ! -e "$amd64_built" ]; do sleep 2; done
      step "$arch: building"
    fi
    at_idle_priority "$AIRSEG_ROOT/packaging/build-debs.sh" --no-check --no-debug-info "$arch"
  fi
}
# record_arm ARCH WALL: the ARCH row of the closing table and of this stage's summary.
record_arm() {
  local arch=$1 wall=$2 obj
  obj="$AIRSEG_ROOT/build-pkg-$1/airseg-$version/obj-$(arch_triplet "$1")"
  if arm_with_suite "$arch"; then
    record_stage "cross: $arch packages, suite under $(qemu_for "$arch")" "$wall" "$obj/ctest-summary.txt" "cross-$arch"
    summary+=("$arch: $wall s wall; $(cat "$obj/ctest-summary.txt" 2>/dev/null || echo 'no ctest summary'); ccache $(ccache_stage_rate "cross-$arch")")
  else
    record_stage "cross: $arch packages, built and checked" "$wall" "" "cross-$arch"
    summary+=("$arch: $wall s wall; packages checked, suite not run; ccache $(ccache_stage_rate "cross-$arch")")
  fi
}

# amd64_packages: the amd64 packages built (without their tests: the whole suite runs natively in CI's sanitize
# stage) and checked, rebuilt as the next version, then installed, upgraded and removed in a throwaway chroot.
# Its rows go to the closing table, its summary line to cross-amd64.summary.
amd64_packages() {
  local start=$SECONDS cpu0 line
  cpu0=$(cpu_seconds)
  step "building amd64 (its tests run in the sanitize stage)"
  ccache_stage_begin cross-amd64
  at_idle_priority "$AIRSEG_ROOT/packaging/build-debs.sh" --no-check --no-debug-info amd64
  record_stage "cross: amd64 packages, built and checked" "$((SECONDS - start))" "" cross-amd64
  [ -z "$amd64_built" ] || touch "$amd64_built"
  line="amd64: $((SECONDS - start)) s wall; packages checked; ccache $(ccache_stage_rate cross-amd64)"
  if [ "${AIRSEG_CI_SKIP_INSTALL_TEST:-0}" != 1 ]; then
    # The virtual machine's boot (a core for minutes, with a time limit) waits for the end of the suite this
    # stage was started beside.
    if [ -n "${AIRSEG_CROSS_SUITE_DONE:-}" ] && [ ! -e "$AIRSEG_CROSS_SUITE_DONE" ]; then
      step "the install test waits for $AIRSEG_CROSS_SUITE_DONE"
      while [ ! -e "$AIRSEG_CROSS_SUITE_DONE" ]; do sleep 5; done
    fi
    # The install test's own copy, from the build's own directory (the ARM builds write dist/ meanwhile),
    # before the rebuild below empties that directory.
    rm -rf "$AIRSEG_CI_LOGS/install-debs" && mkdir -p "$AIRSEG_CI_LOGS/install-debs/next"
    cp "$AIRSEG_ROOT"/build-pkg-amd64/*_"$version"_amd64.deb "$AIRSEG_ROOT"/build-pkg-amd64/*_"$version"_all.deb \
      "$AIRSEG_CI_LOGS/install-debs/"
    start=$SECONDS
    step "the amd64 packages rebuilt as the next version, for the upgrade"
    at_idle_priority "$AIRSEG_ROOT/packaging/build-debs.sh" --no-check --no-debug-info --upgrade-build amd64
    record_stage "cross: amd64 rebuilt as the next version" "$((SECONDS - start))" "" ""
    line="$line; rebuilt as the next version in $((SECONDS - start)) s"
    cp "$AIRSEG_ROOT"/dist/upgrade-test/*.deb "$AIRSEG_CI_LOGS/install-debs/next/"
    start=$SECONDS
    step "install / upgrade / remove test of the amd64 packages"
    if ! "$AIRSEG_ROOT/packaging/test-install.sh" "$AIRSEG_CI_LOGS/install-debs" \
      "$AIRSEG_CI_LOGS/install-debs/next" >"$AIRSEG_CI_LOGS/test-install.log" 2>&1; then
      cat "$AIRSEG_CI_LOGS/test-install.log"
      die "the install / upgrade / remove test failed"
    fi
    cat "$AIRSEG_CI_LOGS/test-install.log"
    record_stage "cross: amd64 install, upgrade, remove (chroot)" "$((SECONDS - start))" "" ""
    start=$SECONDS
    step "the amd64 packages booted under systemd in a virtual machine"
    if ! "$AIRSEG_ROOT/packaging/test-vm.sh" "$AIRSEG_CI_LOGS/install-debs" \
      "$AIRSEG_CI_LOGS/install-debs/next" >"$AIRSEG_CI_LOGS/test-vm.log" 2>&1; then
      cat "$AIRSEG_CI_LOGS/test-vm.log"
      die "the packages' checks under systemd in a virtual machine failed"
    fi
    cat "$AIRSEG_CI_LOGS/test-vm.log"
    record_stage "cross: amd64 booted under systemd (qemu VM)" "$((SECONDS - start))" "" ""
    line="$line; VM checks in $((SECONDS - start)) s"
  fi
  echo "$line; $(($(cpu_seconds) - cpu0)) CPU-s in all" >"$AIRSEG_CI_LOGS/cross-amd64.summary"
}

# renice_tree PID LEVEL: PID and every process under it at nice LEVEL (those started later inherit it), but for
# a suite (tools/run-ctest.sh), which runs at nice 0 whatever its build does.
renice_tree() {
  local pid
  # By its command line: run through env and bash, the script's process is named "bash".
  for pid in $(process_tree "$1" '^([^ ]*/)?((ba)?sh [^ ]*)?run-ctest\.sh( |$)'); do
    renice -n "$2" -p "$pid" >/dev/null 2>&1 || true
  done
}

arm_arches=()
with_amd64=0
for arch in "${arches[@]}"; do
  if [ "$arch" = amd64 ]; then with_amd64=1; else arm_arches+=("$arch"); fi
done
# The build whose suite is longest first, whatever the order asked: armel's (under qemu-arm without a hardware
# FPU, about 990 s warm against armhf's 720), then armhf, then arm64 (no suite). The suites' chains of the
# simulated rover run side by side (tools/run-ctest.sh), so the stage ends with the suite that starts last.
ordered=()
for arch in armel armhf arm64; do
  [[ " ${arm_arches[*]} " != *" $arch "* ]] || ordered+=("$arch")
done
arm_arches=("${ordered[@]}")
overlap=${AIRSEG_CROSS_OVERLAP:-1}
[ ${#arm_arches[@]} -gt 0 ] || overlap=0
# Side by side with amd64, the ARM builds without a suite start once the amd64 packages are built (build_arm),
# whether that build passed or not (its failure fails the stage at the end).
amd64_built=""
if [ "$with_amd64" = 1 ] && [ "$overlap" = 1 ]; then
  amd64_built=$AIRSEG_CI_LOGS/cross-amd64.built
  rm -f "$amd64_built"
fi
if [ "$with_amd64" = 1 ] && [ "$overlap" = 0 ]; then
  amd64_packages
fi

if [ "$overlap" = 1 ]; then
  # The ARM builds side by side: compiles are CPU-bound, the suites under qemu mostly wait on real time. Each
  # build runs at a lower priority than the one before it (nice 0, 10, 19), so the first one's compile has
  # the CPU and the next compile takes what is left; the suites' CPU-bound parts run one at a time, their
  # simulated-rover chains side by side, each at nice 0 again (tools/run-ctest.sh takes AIRSEG_TEST_LOCK and
  # renices itself), so a suite always comes before any compile. The suite's cases then see what they see on a
  # board that does other work too.
  # Started beside another suite (CI starts this stage at nice 14 beside the ASan+UBSan suite), the builds are
  # three apart: armel (whose suite is longest) at the stage's own priority, armhf 3 below, arm64 at 19.
  arm_pids=() level=$(nice) level_step=10
  [ -z "${AIRSEG_CROSS_SUITE_DONE:-}" ] || level_step=3
  step "cross-building ${arm_arches[*]} side by side (from nice $(nice), each next one at $level_step more, at most 19), the suites at nice 0 (their rover chains side by side)"
  # The lock CI's other suites take too when it starts this stage beside them (tools/build-and-test.sh).
  export AIRSEG_TEST_LOCK=${AIRSEG_TEST_LOCK:-$AIRSEG_CI_LOGS/arm-suite.lock}
  for arch in "${arm_arches[@]}"; do
    (
      t=$SECONDS
      code=0
      renice -n "$level" -p "$BASHPID" >/dev/null
      build_arm "$arch" >"$AIRSEG_CI_LOGS/cross-$arch.log" 2>&1 || code=$?
      echo "$((SECONDS - t)) $code" >"$AIRSEG_CI_LOGS/cross-$arch.result"
      exit "$code"
    ) &
    arm_pids+=($!)
    level=$((level + level_step > 19 ? 19 : level + level_step))  # relative to this script's own priority
  done
  # Started beside another suite, the builds move up once it has ended, each still below the suites (nice 0),
  # one of which runs from then on: armel 10, armhf 15, arm64 19. A build's suite already running keeps its
  # nice 0.
  renice_pid=""
  if [ -n "${AIRSEG_CROSS_SUITE_DONE:-}" ]; then
    (
      while [ ! -e "$AIRSEG_CROSS_SUITE_DONE" ]; do sleep 5; done
      level=10
      for pid in "${arm_pids[@]}"; do
        renice_tree "$pid" "$level"
        level=$((level + 5 > 19 ? 19 : level + 5))
      done
    ) &
    renice_pid=$!
  fi
  # The amd64 packages at the lowest priority beside them (the ARM suites come first; its compile takes the
  # CPU they leave), then its install test, which mostly downloads.
  amd64_pid=""
  if [ "$with_amd64" = 1 ]; then
    (
      code=0
      renice -n 19 -p "$BASHPID" >/dev/null
      amd64_packages >"$AIRSEG_CI_LOGS/cross-amd64.log" 2>&1 || code=$?
      touch "$amd64_built"
      exit "$code"
    ) &
    amd64_pid=$!
  fi
  failed=()
  for i in "${!arm_arches[@]}"; do
    arch=${arm_arches[$i]}
    wait "${arm_pids[$i]}" || failed+=("$arch")
    step "$arch finished: $(cut -d' ' -f1 "$AIRSEG_CI_LOGS/cross-$arch.result") s; log:"
    sed "s/^/$arch| /" "$AIRSEG_CI_LOGS/cross-$arch.log"
    record_arm "$arch" "$(cut -d' ' -f1 "$AIRSEG_CI_LOGS/cross-$arch.result")"
  done
  if [ -n "$amd64_pid" ]; then
    wait "$amd64_pid" || failed+=(amd64)
    step "amd64 finished; log:"
    sed "s/^/amd64| /" "$AIRSEG_CI_LOGS/cross-amd64.log"
  fi
  [ -z "$renice_pid" ] || kill "$renice_pid" 2>/dev/null || true
  [ ${#failed[@]} = 0 ] || die "the package build for ${failed[*]} failed (logs: $AIRSEG_CI_LOGS/cross-ARCH.log)"
else
  for arch in "${arm_arches[@]}"; do
    start=$SECONDS
    step "cross-building $arch$(arm_with_suite "$arch" && echo " and running its suite under $(qemu_for "$arch")")"
    build_arm "$arch"
    record_arm "$arch" "$((SECONDS - start))"
  done
fi

for deb in "$AIRSEG_ROOT"/dist/*.deb; do
  echo "== $(basename "$deb")"
  dpkg-deb --info "$deb" | sed -n '/^ Package:/,$p'
done
step "done"
[ ! -f "$AIRSEG_CI_LOGS/cross-amd64.summary" ] || summary=("$(cat "$AIRSEG_CI_LOGS/cross-amd64.summary")" "${summary[@]}")
printf 'ci-cross: %s\n' "${summary[@]}"
