#!/usr/bin/env bash
# run-ctest.sh BUILD_DIR [CTEST_ARGS...]
#
# Runs a build's ctest suite the way CI does (tools/build-and-test.sh, and debian/rules inside the package
# builds), and says in one line what happened:
#   - Every case runs once. A case that fails is a failure, unless tests/ci-rerun.txt names it (with its cause,
#     recorded in docs/reliability.md): such a case runs again, at most twice, and every failure before its pass
#     is printed as "ctest: RERUN NAME: failed, passed at attempt K". No flight-plan, autopilot or system-suite
#     case is ever rerun, whatever the file says.
#   - With AIRSEG_TEST_LOCK set (CI's suites, which run while other builds compile), it runs at nice 0, never
#     behind a compile, and shares the machine with other suites by three locks (tools/ci-lib.sh):
#       - the suite's cases of a resource lock (the label simulated_rover_chains: the simulated rover's
#         chains, one at a time, mostly waiting on real time; "chains" in the log) start at once, beside those
#         of other suites, under a shared lock;
#       - the other cases ("rest": most of the suite's CPU) wait for one of AIRSEG_SUITES_AT_ONCE (default 1)
#         suite slots; they run beside the chains of their own suite, as in one ctest run, and of others;
#       - the cases labelled "alone" (pace measurements) have a suite slot and the chains' lock to themselves:
#         nothing of any suite beside them. They come first when nothing else runs (CI's first suite), else
#         after the suite's chains.
#     AIRSEG_CHAINS_APART=0, or AIRSEG_SUITES_AT_ONCE above 1, runs the whole suite as one ctest run in a suite
#     slot instead.
#   - BUILD_DIR/ctest-summary.txt gets "passed=N failed=N skipped=N reruns=NAME,NAME", and
#     BUILD_DIR/ctest-failed.txt one line per case that failed: its name, a tab, and why (its first assertion
#     failure and the lines after it, or the last lines it printed); both are read by the table at the end of
#     CI's log, where only the end of a long log may be seen.
# CTEST_ARGS go to every ctest run (e.g. -j8 --timeout 600 --exclude-regex ...). Exit status: 0 when every case
# passed (a rerun one included), 1 otherwise.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
dir=$(cd "${1:?usage: run-ctest.sh BUILD_DIR [CTEST_ARGS...]}" && pwd)
shift
. "$top/tools/ci-lib.sh"

# junit_field FILE ATTRIBUTE: an attribute of the <testsuite> element.
junit_field() { sed -n "s/^[[:space:]]*$2=\"\([0-9]*\)\".*/\1/p" "$1" | head -n1; }
# junit_failed FILE: the names of the cases that failed, one per line.
junit_failed() { sed -n 's/^[[:space:]]*<testcase name="\([^"]*\)".* status="fail".*/\1/p' "$1"; }
# xml_text: XML's escapes undone (a case's name as ctest knows it: GetParam() = "modern").
xml_text() { sed 's/&lt;/</g; s/&gt;/>/g; s/&quot;/"/g; s/&apos;/'"'"'/g; s/&amp;/\&/g'; }
regex_quote() { sed 's/[][\.*^$+?(){}|]/\\&/g'; }
# junit_why FILE NAME: why case NAME failed, on one line of at most 600 characters: from its output, the first
# gtest failure and the four lines after it, or (a timeout, a crash) its run time and the last four lines it
# printed.
junit_why() {
  awk -v want="<testcase name=\"$2\"" '
    index($0, want) == 1 || index($0, "\t" want) == 1 {
      inside = 1
      if (match($0, /time="[0-9.]+"/)) took = substr($0, RSTART + 6, RLENGTH - 7)
      next
    }
    inside && /<\/testcase>/ { exit }
    inside {
      gsub(/<\/?system-out>|<failure[^>]*>/, ""); gsub(/[\t ]+/, " "); sub(/^ /, "")
      if ($0 != "" && $0 != " ") out[++n] = $0
    }
    END {
      for (i = 1; i <= n; i++) if (out[i] ~ /(: Failure|^unknown file: .*)$/) break
      from = i <= n ? i : (n > 4 ? n - 3 : 1)
      line = i <= n ? "" : "no assertion failed (a timeout or a crash?) after " took " s; it printed last:"
      for (i = from; i <= n && i < from + 5; i++) line = line (line == "" ? "" : " | ") out[i]
      print line
    }' "$1" | xml_text | tr -d '\r' | cut -c1-600
}

# run_cases PART [CTEST_ARGS...]: one ctest run of the cases CTEST_ARGS select, then the reruns
# tests/ci-rerun.txt allows. Leaves BUILD_DIR/ctest-PART.result ("TOTAL SKIPPED"), ctest-PART.failed (a case
# per line: name, a tab, why) and ctest-PART.reruns (the cases that passed only on a rerun). Lock file
# descriptors (8, 9) are closed for ctest: a process a test leaves behind must not hold a lock.
run_cases() {
  local part=$1 code=0 total skipped attempt=1 name k why xml pattern allowed never
  local -a failed rerun final_failed reruns still
  shift
  rm -f "$dir/ctest-$part"-attempt-*.xml "$dir/ctest-$part.result" "$dir/ctest-$part.failed" \
    "$dir/ctest-$part.reruns"
  local first="$dir/ctest-$part-attempt-1.xml"
  ctest --test-dir "$dir" --output-on-failure --output-junit "$first" "$@" 8>&- 9>&- || code=$?
  if [ ! -f "$first" ]; then
    echo "ctest: no result file (ctest exit $code)" >&2
    echo "0 0" >"$dir/ctest-$part.result"
    printf '%s\t\n' "(no result file: ctest exit $code)" >"$dir/ctest-$part.failed"
    return 1
  fi
  total=$(junit_field "$first" tests)
  skipped=$(($(junit_field "$first" skipped) + $(junit_field "$first" disabled)))
  mapfile -t failed < <(junit_failed "$first")

  # Cases tests/ci-rerun.txt allows a rerun ("REGEX: cause" per line), never one of the three suites whose
  # failures must show at their first run.
  allowed=$(sed -n 's/^\([^#][^:]*\):.*/\1/p' "$top/tests/ci-rerun.txt" 2>/dev/null | paste -sd'|' -)
  never='Flightplan|Autopilot|GcsEndpoint|System'
  rerun=() final_failed=() reruns=()
  for name in "${failed[@]}"; do
    if [ -n "$allowed" ] && [[ "$name" =~ $allowed ]] && ! [[ "$name" =~ $never ]]; then
      rerun+=("$name")
    else
      final_failed+=("$name")
    fi
  done
  while [ ${#rerun[@]} -gt 0 ] && [ $attempt -lt 3 ]; do
    attempt=$((attempt + 1))
    pattern="^($(printf '%s\n' "${rerun[@]}" | xml_text | regex_quote | paste -sd'|' -))\$"
    echo "ctest: attempt $attempt of ${#rerun[@]} case(s) tests/ci-rerun.txt allows to rerun: $(printf '%s\n' "${rerun[@]}" | xml_text | paste -sd' ' -)"
    ctest --test-dir "$dir" --output-on-failure --output-junit "$dir/ctest-$part-attempt-$attempt.xml" "$@" \
      -R "$pattern" 8>&- 9>&- || true
    mapfile -t still < <(junit_failed "$dir/ctest-$part-attempt-$attempt.xml")
    for name in "${rerun[@]}"; do
      if ! printf '%s\n' "${still[@]}" | grep -qxF -- "$name"; then
        echo "ctest: RERUN $(xml_text <<<"$name"): failed, passed at attempt $attempt"
        reruns+=("$name")
      fi
    done
    rerun=("${still[@]}")
  done
  final_failed+=("${rerun[@]}")
  # ctest failed without a failing case: a case that could not run.
  [ "$code" = 0 ] || [ ${#failed[@]} -gt 0 ] || final_failed+=("(ctest exit $code: a case not run)")

  echo "${total:-0} ${skipped:-0}" >"$dir/ctest-$part.result"
  printf '%s\n' "${reruns[@]}" | sed '/^$/d' | xml_text >"$dir/ctest-$part.reruns"
  for name in "${final_failed[@]}"; do
    # The last attempt in which the case ran holds its latest failure.
    why=
    for ((k = attempt; k >= 1; k--)); do
      xml="$dir/ctest-$part-attempt-$k.xml"
      [ -f "$xml" ] && grep -qF "<testcase name=\"$name\"" "$xml" && { why=$(junit_why "$xml" "$name"); break; }
    done
    printf '%s\t%s\n' "$(xml_text <<<"$name")" "$why"
  done >"$dir/ctest-$part.failed"
  [ ${#final_failed[@]} = 0 ]
}

# The parts of the suite, and how they are run: one ctest run, or the chains apart (see the top).
rm -f "$dir"/ctest-*.xml "$dir"/ctest-*.result "$dir"/ctest-*.failed "$dir"/ctest-*.reruns \
  "$dir/ctest-summary.txt" "$dir/ctest-failed.txt"
chains='simulated_rover_chains'
apart=0
if [ -n "${AIRSEG_TEST_LOCK:-}" ] && [ "${AIRSEG_CHAINS_APART:-1}" != 0 ] && [ "${AIRSEG_SUITES_AT_ONCE:-1}" = 1 ]; then
  # The cases are listed once first: gtest_discover_tests lists an executable's cases when ctest first reads
  # them, and two ctest runs at once must not both write those lists.
  suite_priority
  if ctest --test-dir "$dir" -N -L "(^|/)$chains(/|\$)" "$@" 8>&- 9>&- | grep -q '^Total Tests: [1-9]'; then
    apart=1
  fi
fi
# run_alone: the cases labelled alone, with the machine to themselves (the caller holds the locks).
run_alone() {
  local t=$SECONDS
  run_cases alone "$@" -L '(^|/)alone$' 2>&1 | sed -u 's/^/alone| /' || true
  echo "ctest: the alone cases took $((SECONDS - t)) s"
}
start=$SECONDS
if [ "$apart" = 0 ]; then
  parts=(all)
  take_suite_slot
  run_cases all "$@" || true
else
  parts=(rest chains alone)
  echo "ctest: the chains (label $chains) beside other suites' cases, the rest in a suite slot, the alone cases" \
    "first if nothing else runs, else last"
  # The alone cases first when no other suite runs anything (CI's first suite): they then never wait for
  # chains that started later. Otherwise after this suite's chains.
  alone_first=0
  if take_suite_slot now; then
    if take_chains_lock exclusive now; then
      alone_first=1
      run_alone "$@"
    fi
    exec 8>&- 9>&-
  fi
  (
    t=$SECONDS
    take_chains_lock shared
    run_cases chains "$@" -L "(^|/)$chains(/|\$)" -LE '(^|/)alone$' 2>&1 | sed -u 's/^/chains| /' || true
    echo "ctest: the chains took $((SECONDS - t)) s"
    exec 8>&-
    if [ "$alone_first" = 0 ]; then
      t=$SECONDS
      take_suite_slot
      take_chains_lock exclusive
      echo "ctest: the alone cases waited $((SECONDS - t)) s for the machine"
      run_alone "$@"
    fi
  ) &
  chains_pid=$!
  take_suite_slot
  t=$SECONDS
  run_cases rest "$@" -LE "(^|/)($chains|alone)(/|\$)" || true
  echo "ctest: the rest took $((SECONDS - t)) s"
  exec 9>&-
  wait "$chains_pid" || true
fi

# The parts' results, as one suite's.
total=0 skipped=0
final_failed=() reruns=()
for part in "${parts[@]}"; do
  if ! read -r t s 2>/dev/null <"$dir/ctest-$part.result"; then
    t=0 s=0
    printf '%s\t\n' "($part: no result)" >>"$dir/ctest-$part.failed"
  fi
  total=$((total + t)) skipped=$((skipped + s))
  mapfile -t -O ${#final_failed[@]} final_failed < <(cut -f1 "$dir/ctest-$part.failed" 2>/dev/null)
  mapfile -t -O ${#reruns[@]} reruns < <(cat "$dir/ctest-$part.reruns" 2>/dev/null)
  cat "$dir/ctest-$part.failed" >>"$dir/ctest-failed.txt" 2>/dev/null || true
done
# A suite that finds no test at all is a failure, not a pass.
if [ "$total" = 0 ]; then
  final_failed+=("(no test found)")
  printf '%s\t\n' "(no test found)" >>"$dir/ctest-failed.txt"
fi
[ -s "$dir/ctest-failed.txt" ] || rm -f "$dir/ctest-failed.txt"
n_failed=${#final_failed[@]}
passed=$((total - skipped - n_failed))
[ "$passed" -ge 0 ] || passed=0
echo "passed=$passed failed=$n_failed skipped=$skipped reruns=$(IFS=,; echo "${reruns[*]}")" >"$dir/ctest-summary.txt"
echo "ctest: $passed passed, $n_failed failed, $skipped skipped in $((SECONDS - start)) s"
[ ${#reruns[@]} = 0 ] || echo "ctest: ${#reruns[@]} of them passed only on a rerun: ${reruns[*]}"
for name in "${final_failed[@]}"; do
  echo "ctest: FAILED $name"
done
[ "$n_failed" = 0 ]
