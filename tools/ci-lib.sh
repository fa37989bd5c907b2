# Shared by tools/build-and-test.sh and the packaging scripts: the compiler cache's settings, its hit rate per
# stage, and the table of stages that ends CI's log. Sourced, never run.
# shellcheck shell=bash

# airseg_ccache_env TOP: exports the compiler cache's settings for builds of the tree at TOP, so that they
# reach every compile, the package builds' included (debhelper gives a package build a HOME of its own, where
# ccache would start empty and without the user's configuration):
#   CCACHE_DIR      the cache this user's ccache uses anyway (`ccache -k cache_dir`: ~/.cache/ccache unless
#                   configured), so a developer's builds and a CI run on the same machine share it;
#   CCACHE_BASEDIR  TOP: paths under it are rewritten relative to the compile's directory, so a clone of the
#                   tree in another directory hits what this one stored (with -ffile-prefix-map, which the CI
#                   builds use, AIRSEG_RELATIVE_PATHS and Debian's default flags, the objects are identical);
#   CCACHE_DEPEND   1: a compile is looked up by its source's and included files' text (direct mode; the
#                   unity batches are the same bytes in every clone, cmake/AirsegUnity.cmake), and a miss is
#                   stored with the include list the compiler writes anyway (-MD), never running the
#                   preprocessor a second time: about 0.7 CPU-s a batch, on every miss and every hit that the
#                   preprocessor's output would otherwise have had to find (CCACHE_NODEPEND=1 turns it off;
#                   ccache refuses CCACHE_DEPEND=0);
#   CCACHE_MAXSIZE  at least 10 GB: one CI run stores about 1.5 GB (5 build configurations), and developers'
#                   builds share the cache.
airseg_ccache_env() {
  command -v ccache >/dev/null || return 0
  local size
  CCACHE_DIR=${CCACHE_DIR:-$(ccache -k cache_dir)}
  export CCACHE_DIR
  export CCACHE_BASEDIR=$1
  [ -n "${CCACHE_DEPEND:-}${CCACHE_NODEPEND:-}" ] || export CCACHE_DEPEND=1
  size=$(ccache -k max_size)
  case "$size" in
    *G) [ "${size%%[.G]*}" -ge 10 ] || export CCACHE_MAXSIZE=10G ;;
    *) export CCACHE_MAXSIZE=10G ;;
  esac
}

# take_suite_slot: with AIRSEG_TEST_LOCK set, waits for one of its AIRSEG_SUITES_AT_ONCE (default 1) slots and
# holds it on file descriptor 9 until that is closed or the process ends, then runs the caller at nice 0, so that
# no compile beside a suite ever comes before its cases. The caller starts its tests with 9>&-: a process a test
# leaves behind must not hold the lock. CI's suites (ASan+UBSan, TSan, armhf, armel) take it: one runs at a
# time, whatever compiles meanwhile (tools/run-ctest.sh runs a suite's chains of the simulated rover beside it).
# With "now": takes a free slot or returns 1 at once.
# shellcheck disable=SC2120 # the argument is optional
take_suite_slot() {
  [ -n "${AIRSEG_TEST_LOCK:-}" ] || return 0
  local slot
  [ "${1:-}" = now ] || echo "suite: waiting for one of ${AIRSEG_SUITES_AT_ONCE:-1} slot(s) of $AIRSEG_TEST_LOCK"
  while :; do
    for ((slot = 0; slot < ${AIRSEG_SUITES_AT_ONCE:-1}; slot++)); do
      exec 9>>"$AIRSEG_TEST_LOCK.$slot"
      flock -n 9 && break 2
      exec 9>&-
    done
    [ "${1:-}" != now ] || return 1
    sleep 2
  done
  suite_priority
}

# suite_priority: this shell, and what it starts from then on, at nice 0.
suite_priority() {
  renice -n 0 -p "$BASHPID" >/dev/null 2>&1 || echo "suite: cannot run at nice 0 (not root): staying at nice $(nice)"
}

# take_chains_lock shared|exclusive [now]: AIRSEG_TEST_LOCK's chains lock on file descriptor 8. The suites'
# chains of the simulated rover hold it shared (any number of suites' chains at once); a suite's pace
# measurements hold it exclusive, with a suite slot: nothing of any suite beside them. With "now": takes it or
# returns 1 at once.
take_chains_lock() {
  local mode=-x
  [ "$1" != shared ] || mode=-s
  exec 8>>"$AIRSEG_TEST_LOCK.chains"
  flock ${2:+-n} "$mode" 8 && return 0
  exec 8>&-
  return 1
}

# process_tree PID [SKIP]: PID and every process under it, one per line, each after the processes under it (the
# order to stop them in). SKIP, an extended regular expression, leaves out a process whose command line matches
# it, with everything under it.
process_tree() {
  local child args
  args=$(ps -o args= -p "$1" 2>/dev/null) || return 0
  [ -z "${2:-}" ] || ! [[ "$args" =~ $2 ]] || return 0
  for child in $(ps -o pid= --ppid "$1" 2>/dev/null); do
    process_tree "$child" "${2:-}"
  done
  echo "$1"
}

# ccache_stage_begin NAME: this stage's compiles are counted apart (CCACHE_STATSLOG, one line per result), so
# other users of the cache (developers building meanwhile) do not blur its hit rate.
ccache_stage_begin() {
  command -v ccache >/dev/null || return 0
  mkdir -p "$AIRSEG_CI_LOGS"
  export CCACHE_STATSLOG="$AIRSEG_CI_LOGS/ccache-$1.log"
  : >"$CCACHE_STATSLOG"
}

# ccache_stage_rate NAME: "H/N (P %)" for the stage's compiles: hits over cacheable compiles; "-" for none.
ccache_stage_rate() {
  local log="$AIRSEG_CI_LOGS/ccache-$1.log" hits misses
  [ -f "$log" ] || { echo "-"; return; }
  hits=$(grep -cE '^(direct|preprocessed)_cache_hit$' "$log" || true)
  misses=$(grep -cx 'cache_miss' "$log" || true)
  if [ $((hits + misses)) = 0 ]; then
    echo "-"
  else
    echo "$hits/$((hits + misses)) ($((100 * hits / (hits + misses))) %)"
  fi
}

# cpu_sampler_start: the machine's CPU time (/proc/stat's first line: user, nice, system, idle, iowait, in clock
# ticks since boot) written with the time every 5 s to $AIRSEG_CI_LOGS/cpu.log, until the calling shell ends, so
# that each stage's row says how busy the machine was meanwhile: whether a stage left a core idle, and how much
# of the CPU went to work at nice above 0 (CI's compiles beside a suite) rather than at nice 0 (the suites).
cpu_sampler_start() {
  local parent=$$
  mkdir -p "$AIRSEG_CI_LOGS"
  : >"$AIRSEG_CI_LOGS/cpu.log"
  (
    exec 9>&-
    while kill -0 "$parent" 2>/dev/null; do
      cpu_sample >>"$AIRSEG_CI_LOGS/cpu.log"
      sleep 5
    done
  ) &
  # shellcheck disable=SC2034  # the caller stops it
  cpu_sampler_pid=$!
}
# cpu_sample: "EPOCH USER NICE SYSTEM IDLE IOWAIT" now.
cpu_sample() {
  local _cpu user nice system idle iowait _rest
  read -r _cpu user nice system idle iowait _rest </proc/stat
  echo "$(date +%s) $user $nice $system $idle $iowait"
}
# cpu_busy_since EPOCH: "B % (N % niced)": the share of the machine's CPU time that was busy from the last sample
# at or before EPOCH until now, and the share spent at nice above 0; "-" without samples.
cpu_busy_since() {
  local log="$AIRSEG_CI_LOGS/cpu.log"
  [ -s "$log" ] || { echo "-"; return; }
  { cat "$log"; cpu_sample; } | awk -v from="$1" '
    $1 <= from || !have { t = $1; u = $2; n = $3; s = $4; i = $5; w = $6; have = 1 }
    END { du = $2 - u; dn = $3 - n; ds = $4 - s; all = du + dn + ds + ($5 - i) + ($6 - w)
          if (all <= 0) print "-"; else printf "%d %% (%d %% niced)\n", 100 * (du + dn + ds) / all, 100 * dn / all }'
}

# record_stage NAME WALL_SECONDS [SUMMARY_FILE] [CCACHE_STAGE]: one row of the closing table. SUMMARY_FILE is
# a ctest-summary.txt from tools/run-ctest.sh ("passed=N failed=N skipped=N reruns=A,B"); the ctest-failed.txt
# beside it (a failed case's name, a tab and why, per line) goes to the list of failed cases printed under the
# table.
record_stage() {
  local name=$1 wall=$2 summary=${3:-} cstage=${4:-} passed=- failed=- skipped=- reruns=- rate=- busy=-
  if [ -n "$summary" ] && [ -f "$summary" ]; then
    passed=$(sed -n 's/.*passed=\([0-9?]*\).*/\1/p' "$summary")
    failed=$(sed -n 's/.*failed=\([0-9?]*\).*/\1/p' "$summary")
    skipped=$(sed -n 's/.*skipped=\([0-9?]*\).*/\1/p' "$summary")
    reruns=$(sed -n 's/.*reruns=\(.*\)$/\1/p' "$summary")
    reruns=${reruns:-none}
  elif [ -n "$summary" ]; then
    failed="?"
  fi
  [ -z "$cstage" ] || rate=$(ccache_stage_rate "$cstage")
  [[ "$wall" =~ ^[0-9]+$ ]] && busy=$(cpu_busy_since "$(($(date +%s) - wall))")
  mkdir -p "$AIRSEG_CI_LOGS"
  if [ -n "$summary" ] && [ -s "$(dirname "$summary")/ctest-failed.txt" ]; then
    sed "s/^/$name\t/" "$(dirname "$summary")/ctest-failed.txt" >>"$AIRSEG_CI_LOGS/failed.tsv"
  fi
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "$wall" "$passed" "$failed" "$skipped" "$rate" "$busy" "$reruns" \
    >>"$AIRSEG_CI_LOGS/stages.tsv"
}

# print_stage_table TOTAL_SECONDS: the table of every recorded stage, one plain line of test counts, then each
# failed case with its stage (the end of the log is what a reader of a failed run sees first).
print_stage_table() {
  local table="$AIRSEG_CI_LOGS/stages.tsv" p=0 f=0 s=0
  [ -f "$table" ] || return 0
  echo
  echo "== CI stages (wall seconds; tests passed / failed / skipped; compiles served by ccache; the machine's CPU"
  echo "   busy during the stage, and the part of it at nice above 0; reruns)"
  {
    printf 'stage\twall s\tpassed\tfailed\tskipped\tccache hits\tCPU busy\treruns\n'
    cat "$table"
    printf 'total\t%s\t\t\t\t\t%s\t\n' "$1" "$(cpu_busy_since "$(($(date +%s) - $1))")"
  } | awk -F'\t' '{ printf "%-44s %7s %7s %7s %8s  %-18s %-19s %s\n", $1, $2, $3, $4, $5, $6, $7, $8 }'
  while IFS=$'\t' read -r _ _ passed failed skipped _ _ _; do
    [[ "$passed" =~ ^[0-9]+$ ]] && p=$((p + passed))
    [[ "$failed" =~ ^[0-9]+$ ]] && f=$((f + failed))
    [[ "$failed" == "?" ]] && f=$((f + 1))
    [[ "$skipped" =~ ^[0-9]+$ ]] && s=$((s + skipped))
  done <"$table"
  echo "tests: $p passed, $f failed, $s skipped"
  [ -s "$AIRSEG_CI_LOGS/failed.tsv" ] || return 0
  awk -F'\t' '{ n[$1]++
               if (n[$1] <= 20) { print "failed: " $1 ": " $2; if ($3 != "") print "    why: " $3 }
               else if (n[$1] == 21) print "failed: " $1 ": (more in its log)" }' \
    "$AIRSEG_CI_LOGS/failed.tsv"
}
