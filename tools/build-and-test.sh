#!/usr/bin/env bash
# Builds the tree and runs every test stage; .ci/run runs exactly this. Warnings are errors when CI=true.
#
# Stages, in this order (AIRSEG_STAGES chooses a subset, e.g. AIRSEG_STAGES=native):
#   sanitize  clang build of the whole tree with AddressSanitizer, UndefinedBehaviorSanitizer and libFuzzer
#             coverage (build-san/); the whole ctest suite, unit to system tests, any report fails the test
#   tidy      clang-tidy's braces and naming checks (.clang-tidy) on the sources changed since the whole tree
#             last passed them (tools/clang-tidy-check.sh; build-tidy/ is configured, not built); at nice 19
#             beside the sanitize stage's suite when both run
#   fuzz      each libFuzzer target for AIRSEG_FUZZ_SECONDS (default 30) on its seed corpus (tests/fuzz/run.sh,
#             same build directory), one at a time at nice 10 beside the sanitize stage's suite (one per core
#             without it); a crash or a broken property fails the stage
#   tsan      GCC build with ThreadSanitizer (build-tsan/) of the test executables listed in
#             tests/concurrency-tests.txt (the bus and dispatcher, the serial port's threads, the daemon's
#             thread pool running all its services) and the binaries they start; each runs whole, and a race
#             report fails it
#   cross     packaging/ci-cross.sh for the architectures in AIRSEG_CROSS (default "amd64 armhf armel arm64"): the
#             amd64 packages are built and checked (lintian, contents, manual pages against --help) and
#             installed, upgraded and removed in a throwaway chroot, then booted under systemd in a qemu
#             virtual machine (packaging/test-vm.sh); the armhf and armel packages are
#             cross-built with the whole test suite, which runs under qemu-arm; the arm64 packages are
#             cross-built and checked (their suite under qemu-aarch64 with AIRSEG_CROSS_TEST_ARM64=1; needs root)
#   native    GCC build as shipped (build/, the one tools/demo.sh runs) and the whole ctest suite
# With sanitize, the cross stage starts when the sanitizer build is done and compiles at nice 14 to 19 beside the
# ASan+UBSan suite; every suite (ASan+UBSan, TSan, armhf, armel) takes one lock, so that their CPU-bound parts run
# one at a time (their simulated-rover chains side by side: tools/run-ctest.sh), each at nice 0
# (AIRSEG_CROSS_BESIDE_SUITE=0: the cross stage after the others, as without sanitize).
# Default: "sanitize tidy fuzz tsan cross". The shipped GCC build is tested by the cross stage on the two ARM
# targets; "native" repeats that on amd64 and is the quickest check while developing.
# Every compile goes through ccache when it is installed, in the cache this user's ccache uses
# (~/.cache/ccache unless configured), with paths relative to the top of the tree (tools/ci-lib.sh): a second
# run, in this clone or in a fresh one elsewhere on the same machine, compiles almost nothing. Each stage
# says how many of its compiles the cache served. Test suites run through tools/run-ctest.sh (every case
# once; no rerun unless tests/ci-rerun.txt names the case with its cause). The log ends with a table of the
# stages (build-logs/stages.tsv): wall time, tests passed / failed / skipped, ccache hits, how busy the machine's
# CPU was meanwhile (build-logs/cpu.log, sampled every 5 s), reruns.
# docs/operations.md ("CI") has the figures for each stage.
set -euo pipefail
cd "$(dirname "$0")/.."
. tools/ci-lib.sh
export AIRSEG_CI_LOGS=$PWD/build-logs
mkdir -p "$AIRSEG_CI_LOGS"
rm -f "$AIRSEG_CI_LOGS/stages.tsv" "$AIRSEG_CI_LOGS/failed.tsv"
airseg_ccache_env "$PWD"
cpu_sampler_start
stages=${AIRSEG_STAGES:-sanitize tidy fuzz tsan cross}
jobs=$(nproc)
# Test cases at once: most of them wait on real time (the simulated radios and autopilot run at real speed),
# so four per core keep the CPU busy (measured: the suite under ASan uses under half of 2 cores at -j8).
test_jobs=${AIRSEG_TEST_JOBS:-$((4 * jobs))}
export AIRSEG_TEST_JOBS=$test_jobs
total=$SECONDS

# GCC's garbage collector runs first when its heap reaches 1 GiB (by default here 128 MiB, an eighth of the
# memory up to that): the same objects for about 5 % less CPU (an armhf batch of test code 16.3 -> 14.9 CPU-s,
# one of shipped code 14.6 -> 14.0), each compile at about 1.1 GB at most. The TSan build and the package
# builds (packaging/build-debs.sh) add it; clang's sanitizer build has no such parameter.
export AIRSEG_GCC_FLAGS=${AIRSEG_GCC_FLAGS-"--param=ggc-min-heapsize=1048576"}

# The CI builds map the tree's path to . in their objects (AIRSEG_RELATIVE_PATHS), so that a clone elsewhere
# shares their cache entries.
launcher=(-DAIRSEG_RELATIVE_PATHS=ON)
if command -v ccache >/dev/null; then
  launcher+=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

has_stage() { [[ " $stages " == *" $1 "* ]]; }
# elapsed WHAT START [SUMMARY_FILE] [CCACHE_STAGE]: says how long WHAT took and records it for the closing table.
elapsed() {
  echo "build-and-test: $1 in $((SECONDS - $2)) s"
  [ -z "${4:-}" ] || echo "build-and-test: $1: ccache served $(ccache_stage_rate "$4") compiles"
  record_stage "$1" "$((SECONDS - $2))" "${3:-}" "${4:-}"
}
# A process started here in the background, with everything it started.
kill_tree() {
  local pid
  for pid in $(process_tree "$1"); do
    kill "$pid" 2>/dev/null || true
  done
}
# The table ends the log however the run ends; a stage that failed is its last row, and what it left running
# in the background (fuzzers, the TSan build, the cross preparation) is stopped.
finish() {
  local code=$? pid
  if [ "$code" != 0 ]; then
    for pid in ${fuzz_pid:-} ${tsan_build_pid:-} ${tidy_pid:-} ${prepare_pid:-} ${cross_pid:-}; do
      kill_tree "$pid"
    done
    record_stage "FAILED (exit $code) after the stages above" "-" "" ""
  fi
  print_stage_table "$((SECONDS - total))"
  kill "$cpu_sampler_pid" 2>/dev/null || true
}
trap finish EXIT

# The MAVLink interoperability test needs node-mavlink (pinned by its lock file) in each build directory, set up
# (tests/integration/mavlink_interop/setup.sh) before the suite; the ARM suites use build-san's.
run_ctest() {
  local dir=$1
  shift
  tools/run-ctest.sh "$dir" -j"$test_jobs" --timeout 600 "$@"
}

for s in $stages; do
  case "$s" in
    sanitize|tidy|fuzz|tsan|cross|native) ;;
    *) echo "build-and-test: unknown stage '$s' (expected sanitize, tidy, fuzz, tsan, cross, native)" >&2; exit 2 ;;
  esac
done

# The cross stage's downloads (cross compilers, qemu, the ARM sysroots) go on in the background while the
# sanitizer build compiles; the cross stage waits for them.
prepare_pid=""
if has_stage cross && { has_stage sanitize || has_stage fuzz; }; then
  mkdir -p build-logs
  # shellcheck disable=SC2086
  packaging/ci-cross.sh --prepare ${AIRSEG_CROSS:-amd64 armhf armel arm64} >build-logs/cross-prepare.log 2>&1 &
  prepare_pid=$!
fi

if has_stage sanitize || has_stage fuzz; then
  start=$SECONDS
  ccache_stage_begin sanitize-build
  # The same configuration tests/fuzz/run.sh makes, so the fuzz stage reuses this build. The test-only code (the
  # test executables' sources and tests/support) at -O0: clang with ASan+UBSan compiles it in about half the time
  # of -O1 (six test batches: 98 -> 52 CPU-s), about 420 CPU-s of a cold build; the libraries, programs and fuzz
  # targets under test keep -O1.
  CC=clang CXX=clang++ cmake -S . -B build-san -G Ninja "${launcher[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" \
    -DAIRSEG_BUILD_FUZZ=ON -DAIRSEG_BUILD_TESTS=ON -DAIRSEG_BUILD_BENCH=ON -DAIRSEG_TEST_OPTIMIZATION=-O0 \
    -DAIRSEG_TEST_UNITY_BATCH_SIZE=0 \
    -DAIRSEG_SANITIZE=fuzzer-no-link,address,undefined
  cmake --build build-san -j"$jobs"
  elapsed "sanitize: build (clang, ASan+UBSan)" "$start" "" sanitize-build
  tests/integration/mavlink_interop/setup.sh build-san
fi

# Every suite takes a slot of one lock (tools/ci-lib.sh, take_suite_slot): one suite's CPU-bound part at a time,
# at nice 0, with the simulated-rover chains of every suite beside it (tools/run-ctest.sh), while the builds that
# are not testing compile beside them at lower priorities, in the order their suites are needed.
export AIRSEG_TEST_LOCK=${AIRSEG_TEST_LOCK:-$AIRSEG_CI_LOGS/suite.lock}

# With the sanitize stage, the cross stage starts as soon as the sanitizer build is done, at nice 14 beside the
# ASan+UBSan suite (its builds at 14 to 19: armhf, whose suite is needed first, at 14; arm64 and amd64, which
# nothing waits for, at 19): the package compiles take the core that suite leaves idle (one line of simulated-rover
# cases bounds it, not the CPU), and the ARM suites wait for the lock: after the ASan+UBSan suite, before or
# after the TSan run, whichever takes the lock first.
# The amd64 install and boot tests wait for the ASan+UBSan suite's end (AIRSEG_CROSS_SUITE_DONE): the
# virtual machine's boot has a time limit that a core shared with every background job could break.
cross_pid=""
cross_early=0
if has_stage cross && has_stage sanitize && [ "${AIRSEG_CROSS_BESIDE_SUITE:-1}" = 1 ]; then
  cross_early=1
  if [ -n "$prepare_pid" ]; then
    wait "$prepare_pid" || { cat build-logs/cross-prepare.log; echo "build-and-test: cross preparation failed" >&2; exit 1; }
    prepare_pid=""
    cat build-logs/cross-prepare.log
  fi
  export AIRSEG_CROSS_SUITE_DONE=$AIRSEG_CI_LOGS/asan-suite.done
  rm -f "$AIRSEG_CROSS_SUITE_DONE"
  cross_start=$SECONDS
  # shellcheck disable=SC2086
  AIRSEG_INTEROP_MODULES="$PWD/build-san/mavlink_interop/node_modules" \
    nice -n 14 packaging/ci-cross.sh ${AIRSEG_CROSS:-amd64 armhf armel arm64} >build-logs/cross.log 2>&1 &
  cross_pid=$!
fi

# Each libFuzzer target for $seconds from its seeds, $1 at a time; each log ends with libFuzzer's statistics.
fuzz_targets() {
  local parallel=$1 seconds=${AIRSEG_FUZZ_SECONDS:-30} t runs
  mapfile -t targets < <(find build-san/tests/fuzz -maxdepth 1 -type f -name 'fuzz_*' -perm -u+x -printf '%f\n' | sort)
  [ ${#targets[@]} -gt 0 ] || { echo "build-and-test: no fuzz targets in build-san/tests/fuzz" >&2; return 1; }
  # Targets with an open finding (tests/fuzz/ci-skip.txt) would fail every run until it is fixed: said, not run.
  mapfile -t skipped < <(sed -n 's/^\(fuzz_[a-z_]*\):.*/\1/p' tests/fuzz/ci-skip.txt)
  for t in "${skipped[@]}"; do
    echo "fuzz: $t NOT RUN: open finding, see tests/fuzz/ci-skip.txt"
    mapfile -t targets < <(printf '%s\n' "${targets[@]}" | grep -vxF "$t")
  done
  mkdir -p build-san/fuzz-logs
  printf '%s\n' "${targets[@]}" | xargs -P "$parallel" -I{} sh -c \
    'AIRSEG_FUZZ_BUILD_DIR=build-san AIRSEG_FUZZ_PREBUILT=1 tests/fuzz/run.sh {} '"$seconds"' >build-san/fuzz-logs/{}.log 2>&1 \
       || { echo "fuzz: {} FAILED"; tail -n 40 build-san/fuzz-logs/{}.log; exit 255; }' || return 1
  for t in "${targets[@]}"; do
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "build-san/fuzz-logs/$t.log")
    echo "fuzz: $t: ${runs:-?} executions in $seconds s, no finding"
  done
  echo "fuzz: ${#targets[@]} targets, $seconds s each, $parallel at a time"
}

# The fuzzers run beside the ASan+UBSan suite, one at a time at nice 10: most of the suite waits on real time
# and leaves a core idle, which the fuzzers take without delaying the suite's simulated peers. Each runs for a
# fixed time, so its share of that core is its coverage: it comes before the compiles beside it (nice 12 to
# 19; at the same priority as the package compiles the byte-level targets ran a third of their executions).
fuzz_pid=""
if has_stage fuzz && has_stage sanitize; then
  fuzz_start=$SECONDS
  mkdir -p build-logs
  nice -n 10 bash -c "$(declare -f fuzz_targets); fuzz_targets 1" >build-logs/fuzz.log 2>&1 &
  fuzz_pid=$!
fi

# The ThreadSanitizer build of the concurrency tests: in batches like every other build (the tidy stage
# parses each changed source on its own, which is where a missing #include that a batch-mate provides shows),
# each test executable one batch as in the sanitizer build (core_tests had two).
mapfile -t tsan_targets < <(grep '^[a-z]' tests/concurrency-tests.txt)
tsan_build() {
  ccache_stage_begin tsan-build
  cmake -S . -B build-tsan -G Ninja "${launcher[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1${AIRSEG_GCC_FLAGS:+ $AIRSEG_GCC_FLAGS}" -DAIRSEG_BUILD_BENCH=OFF -DAIRSEG_SANITIZE=thread \
    -DAIRSEG_TEST_UNITY_BATCH_SIZE=0
  cmake --build build-tsan -j"$jobs" --target "${tsan_targets[@]}"
}

# The TSan build compiles at nice 12 beside the ASan+UBSan suite, which mostly waits on real time: a core is
# idle there. It comes after the fuzzers (nice 10) and before the package builds (14 to 19): its run is the
# first suite that can follow the ASan+UBSan one, and a cold run's lock stood free waiting for it and for
# armhf's compile. Its log is printed at the tsan stage.
tsan_build_pid=""
if has_stage tsan && has_stage sanitize && [ "${AIRSEG_TSAN_BESIDE_SUITE:-1}" = 1 ]; then
  tsan_start=$SECONDS
  ( renice -n 12 -p "$BASHPID" >/dev/null; tsan_build ) >build-logs/tsan-build.log 2>&1 &
  tsan_build_pid=$!
fi

# clang-tidy, too, at nice 19 beside the suite: it parses each changed source on its own, CPU-bound work for
# the core the suite leaves idle.
tidy_pid=""
if has_stage tidy && has_stage sanitize; then
  tidy_start=$SECONDS
  nice -n 19 tools/clang-tidy-check.sh build-tidy >build-logs/tidy.log 2>&1 &
  tidy_pid=$!
fi

if has_stage sanitize; then
  start=$SECONDS
  # Any sanitizer report ends the process with an error, in the tests and in the programs they start.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:halt_on_error=1 \
    UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 run_ctest build-san || suite=$?
  elapsed "sanitize: whole suite under ASan+UBSan" "$start" build-san/ctest-summary.txt
  [ "${suite:-0}" = 0 ] || exit 1
  [ -z "${AIRSEG_CROSS_SUITE_DONE:-}" ] || touch "$AIRSEG_CROSS_SUITE_DONE"
fi

if [ -n "$tidy_pid" ]; then
  code=0
  wait "$tidy_pid" || code=$?
  cat build-logs/tidy.log
  [ "$code" = 0 ] || { echo "build-and-test: clang-tidy found a problem" >&2; exit 1; }
  elapsed "tidy: clang-tidy on the changed sources, beside the ASan+UBSan suite" "$tidy_start"
elif has_stage tidy; then
  start=$SECONDS
  tools/clang-tidy-check.sh build-tidy
  elapsed "tidy: clang-tidy on the changed sources" "$start"
fi

if [ -n "$fuzz_pid" ]; then
  code=0
  wait "$fuzz_pid" || code=$?
  cat build-logs/fuzz.log
  [ "$code" = 0 ] || { echo "build-and-test: fuzzing found a problem" >&2; exit 1; }
  elapsed "fuzz: every target, beside the ASan+UBSan suite" "$fuzz_start"
elif has_stage fuzz; then
  start=$SECONDS
  fuzz_targets "$jobs"  # one per core
  elapsed "fuzz: every target" "$start"
fi

if has_stage tsan; then
  start=$SECONDS
  if [ -n "$tsan_build_pid" ]; then
    code=0
    wait "$tsan_build_pid" || code=$?
    cat build-logs/tsan-build.log
    [ "$code" = 0 ] || { echo "build-and-test: the ThreadSanitizer build failed" >&2; exit 1; }
    start=$tsan_start
  else
    tsan_build
  fi
  elapsed "tsan: build of the concurrency tests (GCC, TSan)${tsan_build_pid:+, at nice 12 beside the suite}" "$start" "" tsan-build
  take_suite_slot
  start=$SECONDS
  # Each executable runs whole and directly (ctest's label list cannot carry a second label through
  # gtest_discover_tests), all at once: they mostly wait on real time. Each log is printed when it ends.
  mkdir -p build-tsan/logs
  pids=()
  for t in "${tsan_targets[@]}"; do
    exe=$(find build-tsan -type f -name "$t" -perm -u+x | head -n1)
    [ -n "$exe" ] || { echo "build-and-test: $t was not built in build-tsan" >&2; exit 1; }
    TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 timeout 900 "$exe" --gtest_brief=1 \
      >"build-tsan/logs/$t.log" 2>&1 9>&- &
    pids+=($!)
  done
  failed=0 t_passed=0 t_failed=0 t_skipped=0
  : >build-tsan/logs/ctest-failed.txt
  for i in "${!pids[@]}"; do
    code=0
    wait "${pids[$i]}" || code=$?
    echo "tsan: ${tsan_targets[$i]} (exit $code)"
    log="build-tsan/logs/${tsan_targets[$i]}.log"
    cat "$log"
    [ "$code" = 0 ] || failed=1
    # GoogleTest's closing lines: "[  PASSED  ] N tests.", "[  FAILED  ] N tests, listed below:", "[  SKIPPED ] N ..."
    n=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$log" | tail -n1); t_passed=$((t_passed + ${n:-0}))
    n=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$log" | tail -n1); t_failed=$((t_failed + ${n:-0}))
    n=$(sed -n 's/^\[  SKIPPED \] \([0-9]*\) test.*/\1/p' "$log" | tail -n1); t_skipped=$((t_skipped + ${n:-0}))
    [ "$code" = 0 ] || [ -n "$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$log")" ] || t_failed=$((t_failed + 1))
    # The failed cases' names (GoogleTest's list after its "listed below"), or the executable when it died.
    sed -n 's/^\[  FAILED  \] \([A-Za-z_][^ ,]*\.[^ ,]*\)\(,.*\)\{0,1\}$/\1/p' "$log" | sort -u >>build-tsan/logs/ctest-failed.txt
    [ "$code" = 0 ] || grep -q "^\[  FAILED  \]" "$log" || echo "${tsan_targets[$i]} (exit $code)" >>build-tsan/logs/ctest-failed.txt
  done
  echo "passed=$t_passed failed=$t_failed skipped=$t_skipped reruns=" >build-tsan/logs/summary.txt
  elapsed "tsan: the concurrency tests, whole, at once" "$start" build-tsan/logs/summary.txt
  exec 9>&-  # the suite slot
  [ "$failed" = 0 ] || { echo "build-and-test: a ThreadSanitizer run failed" >&2; exit 1; }
fi

if [ "$cross_early" = 1 ]; then
  code=0
  wait "$cross_pid" || code=$?
  cross_pid=""
  cat build-logs/cross.log
  [ "$code" = 0 ] || { echo "build-and-test: the cross stage failed" >&2; exit 1; }
  elapsed "cross: the whole package stage (rows above), from the sanitizer build's end" "$cross_start"
elif has_stage cross; then
  start=$SECONDS
  # The ARM test suites run mavlink_interop too, with the node-mavlink set up in the first build directory.
  modules_dir=build-san
  has_stage sanitize || modules_dir=build-cross-interop
  if [ -n "$prepare_pid" ]; then
    wait "$prepare_pid" || { cat build-logs/cross-prepare.log; echo "build-and-test: cross preparation failed" >&2; exit 1; }
    cat build-logs/cross-prepare.log
  fi
  [ "$modules_dir" = build-san ] || tests/integration/mavlink_interop/setup.sh "$modules_dir"
  # shellcheck disable=SC2086
  AIRSEG_INTEROP_MODULES="$(cd "$modules_dir" && pwd)/mavlink_interop/node_modules" \
    packaging/ci-cross.sh ${AIRSEG_CROSS:-amd64 armhf armel arm64}
  elapsed "cross: the whole package stage (rows above)" "$start"
fi

if has_stage native; then
  start=$SECONDS
  # build/ as the README's first command made it is reused as it is: adding a compiler launcher (or any
  # other option) to a configured tree makes CMake rebuild every step.
  ccache_stage_begin native-build
  if [ -f build/CMakeCache.txt ]; then
    cmake build >/dev/null
  else
    cmake -S . -B build -G Ninja "${launcher[@]}"
  fi
  cmake --build build -j"$jobs"
  elapsed "native: build" "$start" "" native-build
  start=$SECONDS
  tests/integration/mavlink_interop/setup.sh build
  run_ctest build || suite=$?
  elapsed "native: whole suite" "$start" build/ctest-summary.txt
  [ "${suite:-0}" = 0 ] || exit 1
fi

echo "build-and-test: stages '$stages' passed in $((SECONDS - total)) s"
