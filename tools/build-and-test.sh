#!/usr/bin/env bash
# Builds the tree and runs every test stage; .ci/run runs exactly this. Warnings are errors when CI=true.
#
# Stages, in this order (AIRSEG_STAGES chooses a subset, e.g. AIRSEG_STAGES=native):
#   sanitize  clang build of the whole tree with AddressSanitizer, UndefinedBehaviorSanitizer and libFuzzer
#             coverage (build-san/); the whole ctest suite, unit to system tests, any report fails the test
#   tidy      clang-tidy's braces and naming checks (.clang-tidy) on the sources changed since the whole tree
#             last passed them (tools/clang-tidy-check.sh; build-tidy/ is configured, not built)
#   fuzz      each libFuzzer target for AIRSEG_FUZZ_SECONDS (default 30) on its seed corpus (tests/fuzz/run.sh,
#             same build directory), one at a time at nice 19 beside the sanitize stage's suite (one per core
#             without it); a crash or a broken property fails the stage
#   tsan      GCC build with ThreadSanitizer (build-tsan/) of the test executables listed in
#             tests/concurrency-tests.txt (the bus and dispatcher, the serial port's threads, the daemon's
#             thread pool running all its services) and the binaries they start; each runs whole, and a race
#             report fails it
#   cross     packaging/ci-cross.sh for the architectures in AIRSEG_CROSS (default "amd64 armhf armel arm64"): the
#             amd64 packages are built and checked (lintian, contents, manual pages against --help) and
#             installed, upgraded and removed in a throwaway chroot; the armhf and armel packages are
#             cross-built with the whole test suite, which runs under qemu-arm; the arm64 packages are
#             cross-built and checked (their suite under qemu-aarch64 with AIRSEG_CROSS_TEST_ARM64=1; needs root)
#   native    GCC build as shipped (build/, the one tools/demo.sh runs) and the whole ctest suite
# Default: "sanitize tidy fuzz tsan cross". The shipped GCC build is tested by the cross stage on the two ARM
# targets; "native" repeats that on amd64 and is the quickest check while developing.
# docs/operations.md ("CI") has the figures for each stage.
set -euo pipefail
cd "$(dirname "$0")/.."
stages=${AIRSEG_STAGES:-sanitize tidy fuzz tsan cross}
jobs=$(nproc)
# Test cases at once: most of them wait on real time (the simulated radios and autopilot run at real speed),
# so four per core keep the CPU busy (measured: the suite under ASan uses under half of 2 cores at -j8).
test_jobs=${AIRSEG_TEST_JOBS:-$((4 * jobs))}
export AIRSEG_TEST_JOBS=$test_jobs
total=$SECONDS

launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

has_stage() { [[ " $stages " == *" $1 "* ]]; }
elapsed() { echo "build-and-test: $1 in $((SECONDS - $2)) s"; }

# The MAVLink interoperability test needs node-mavlink (pinned by its lock file) in each build directory.
run_ctest() {
  local dir=$1
  shift
  tests/integration/mavlink_interop/setup.sh "$dir"
  ctest --test-dir "$dir" -j"$test_jobs" --output-on-failure --timeout 600 "$@"
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
  # The same configuration tests/fuzz/run.sh makes, so the fuzz stage reuses this build.
  CC=clang CXX=clang++ cmake -S . -B build-san -G Ninja "${launcher[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" \
    -DAIRSEG_BUILD_FUZZ=ON -DAIRSEG_BUILD_TESTS=ON -DAIRSEG_BUILD_BENCH=ON \
    -DAIRSEG_SANITIZE=fuzzer-no-link,address,undefined
  cmake --build build-san -j"$jobs"
  elapsed "sanitizer build" "$start"
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

# The fuzzers run beside the ASan+UBSan suite, one at a time at the lowest priority: most of the suite waits
# on real time and leaves a core idle, which the fuzzers take without delaying the suite's simulated peers.
fuzz_pid=""
if has_stage fuzz && has_stage sanitize; then
  fuzz_start=$SECONDS
  mkdir -p build-logs
  nice -n 19 bash -c "$(declare -f fuzz_targets); fuzz_targets 1" >build-logs/fuzz.log 2>&1 &
  fuzz_pid=$!
fi

if has_stage sanitize; then
  start=$SECONDS
  # Any sanitizer report ends the process with an error, in the tests and in the programs they start.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:halt_on_error=1 \
    UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 run_ctest build-san
  elapsed "tests under ASan+UBSan" "$start"
fi

if has_stage tidy; then
  start=$SECONDS
  tools/clang-tidy-check.sh build-tidy
  elapsed "clang-tidy" "$start"
fi

if [ -n "$fuzz_pid" ]; then
  code=0
  wait "$fuzz_pid" || code=$?
  cat build-logs/fuzz.log
  [ "$code" = 0 ] || { echo "build-and-test: fuzzing found a problem" >&2; exit 1; }
  elapsed "fuzzing, beside the ASan+UBSan suite" "$fuzz_start"
elif has_stage fuzz; then
  start=$SECONDS
  fuzz_targets "$jobs"  # one per core
  elapsed "fuzzing" "$start"
fi

if has_stage tsan; then
  start=$SECONDS
  # In batches like every other build: the tidy stage parses each changed source on its own, which is where a
  # missing #include that a batch-mate provides shows up.
  cmake -S . -B build-tsan -G Ninja "${launcher[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" -DAIRSEG_BUILD_BENCH=OFF -DAIRSEG_SANITIZE=thread
  mapfile -t tsan_targets < <(grep '^[a-z]' tests/concurrency-tests.txt)
  cmake --build build-tsan -j"$jobs" --target "${tsan_targets[@]}"
  # Each executable runs whole and directly (ctest's label list cannot carry a second label through
  # gtest_discover_tests), all at once: they mostly wait on real time. Each log is printed when it ends.
  mkdir -p build-tsan/logs
  pids=()
  for t in "${tsan_targets[@]}"; do
    exe=$(find build-tsan -type f -name "$t" -perm -u+x | head -n1)
    [ -n "$exe" ] || { echo "build-and-test: $t was not built in build-tsan" >&2; exit 1; }
    TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 timeout 900 "$exe" --gtest_brief=1 \
      >"build-tsan/logs/$t.log" 2>&1 &
    pids+=($!)
  done
  failed=0
  for i in "${!pids[@]}"; do
    code=0
    wait "${pids[$i]}" || code=$?
    echo "tsan: ${tsan_targets[$i]} (exit $code)"
    cat "build-tsan/logs/${tsan_targets[$i]}.log"
    [ "$code" = 0 ] || failed=1
  done
  [ "$failed" = 0 ] || { echo "build-and-test: a ThreadSanitizer run failed" >&2; exit 1; }
  elapsed "ThreadSanitizer build and tests" "$start"
fi

if has_stage cross; then
  start=$SECONDS
  # The ARM test suites run mavlink_interop too, with the node-mavlink set up in the first build directory.
  modules_dir=build-san
  has_stage sanitize || modules_dir=build-cross-interop
  if [ -n "$prepare_pid" ]; then
    wait "$prepare_pid" || { cat build-logs/cross-prepare.log; echo "build-and-test: cross preparation failed" >&2; exit 1; }
    cat build-logs/cross-prepare.log
  fi
  tests/integration/mavlink_interop/setup.sh "$modules_dir"
  # shellcheck disable=SC2086
  AIRSEG_INTEROP_MODULES="$(cd "$modules_dir" && pwd)/mavlink_interop/node_modules" \
    packaging/ci-cross.sh ${AIRSEG_CROSS:-amd64 armhf armel arm64}
  elapsed "packages (amd64, and ARM with their tests under qemu-arm)" "$start"
fi

if has_stage native; then
  start=$SECONDS
  # build/ as the README's first command made it is reused as it is: adding a compiler launcher (or any
  # other option) to a configured tree makes CMake rebuild every step.
  if [ -f build/CMakeCache.txt ]; then
    cmake build >/dev/null
  else
    cmake -S . -B build -G Ninja "${launcher[@]}"
  fi
  cmake --build build -j"$jobs"
  run_ctest build
  elapsed "native build and tests" "$start"
fi

echo "build-and-test: stages '$stages' passed in $((SECONDS - total)) s"
