#!/usr/bin/env bash
# run-ctest.sh BUILD_DIR [CTEST_ARGS...]
#
# Runs a build's ctest suite the way CI does (tools/build-and-test.sh, and debian/rules inside the package
# builds), and says in one line what happened:
#   - Every case runs once. A case that fails is a failure, unless tests/ci-rerun.txt names it (with its cause,
#     recorded in docs/reliability.md): such a case runs again, at most twice, and every failure before its pass
#     is printed as "ctest: RERUN NAME: failed, passed at attempt K". No flight-plan, autopilot or system-suite
#     case is ever rerun, whatever the file says.
#   - With AIRSEG_TEST_LOCK set, it waits for that lock first and runs at nice 0 (CI's suites, which run while
#     other builds compile: one suite at a time, or AIRSEG_SUITES_AT_ONCE, never behind a compile).
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

# AIRSEG_TEST_LOCK: one suite at a time (tools/ci-lib.sh, take_suite_slot), at nice 0 whatever the build around
# it was started at.
. "$top/tools/ci-lib.sh"
take_suite_slot

# junit_field FILE ATTRIBUTE: an attribute of the <testsuite> element.
junit_field() { sed -n "s/^[[:space:]]*$2=\"\([0-9]*\)\".*/\1/p" "$1" | head -n1; }
# junit_failed FILE: the names of the cases that failed, one per line.
junit_failed() { sed -n 's/^[[:space:]]*<testcase name="\([^"]*\)".* status="fail".*/\1/p' "$1"; }
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
    }' "$1" | sed 's/&lt;/</g; s/&gt;/>/g; s/&quot;/"/g; s/&apos;/'"'"'/g; s/&amp;/\&/g' | tr -d '\r' | cut -c1-600
}

first="$dir/ctest-attempt-1.xml"
rm -f "$dir"/ctest-attempt-*.xml "$dir/ctest-summary.txt" "$dir/ctest-failed.txt"
code=0
# A suite that finds no test at all is a failure, not a pass.
ctest --test-dir "$dir" --output-on-failure --no-tests=error --output-junit "$first" "$@" 9>&- || code=$?
if [ ! -f "$first" ]; then
  echo "ctest: no result file (ctest exit $code)" >&2
  echo "passed=0 failed=? skipped=0 reruns=" >"$dir/ctest-summary.txt"
  echo "(no result file: ctest exit $code)" >"$dir/ctest-failed.txt"
  exit 1
fi
total=$(junit_field "$first" tests)
skipped=$(($(junit_field "$first" skipped) + $(junit_field "$first" disabled)))
mapfile -t failed < <(junit_failed "$first")

# Cases tests/ci-rerun.txt allows a rerun ("REGEX: cause" per line), never one of the three suites whose
# failures must show at their first run.
allowed=$(sed -n 's/^\([^#][^:]*\):.*/\1/p' "$top/tests/ci-rerun.txt" 2>/dev/null | paste -sd'|' -)
never='Flightplan|Autopilot|GcsEndpoint|System'
rerun=() final_failed=()
for name in "${failed[@]}"; do
  if [ -n "$allowed" ] && [[ "$name" =~ $allowed ]] && ! [[ "$name" =~ $never ]]; then
    rerun+=("$name")
  else
    final_failed+=("$name")
  fi
done

reruns=()
attempt=1
while [ ${#rerun[@]} -gt 0 ] && [ $attempt -lt 3 ]; do
  attempt=$((attempt + 1))
  pattern="^($(printf '%s\n' "${rerun[@]}" | regex_quote | paste -sd'|' -))\$"
  echo "ctest: attempt $attempt of ${#rerun[@]} case(s) tests/ci-rerun.txt allows to rerun: ${rerun[*]}"
  ctest --test-dir "$dir" --output-on-failure --output-junit "$dir/ctest-attempt-$attempt.xml" "$@" \
    -R "$pattern" 9>&- || true
  mapfile -t still < <(junit_failed "$dir/ctest-attempt-$attempt.xml")
  for name in "${rerun[@]}"; do
    if ! printf '%s\n' "${still[@]}" | grep -qxF -- "$name"; then
      echo "ctest: RERUN $name: failed, passed at attempt $attempt"
      reruns+=("$name")
    fi
  done
  rerun=("${still[@]}")
done
final_failed+=("${rerun[@]}")
# ctest failed without a failing case: no test found, or a case that could not run.
[ "$code" = 0 ] || [ ${#failed[@]} -gt 0 ] || final_failed+=("(ctest exit $code: no test found, or a case not run)")

n_failed=${#final_failed[@]}
passed=$((total - skipped - n_failed))
[ "$passed" -ge 0 ] || passed=0
echo "passed=$passed failed=$n_failed skipped=$skipped reruns=$(IFS=,; echo "${reruns[*]}")" >"$dir/ctest-summary.txt"
if [ "$n_failed" != 0 ]; then
  for name in "${final_failed[@]}"; do
    # The last attempt in which the case ran holds its latest failure.
    why=
    for ((k = attempt; k >= 1; k--)); do
      xml="$dir/ctest-attempt-$k.xml"
      [ -f "$xml" ] && grep -qF "<testcase name=\"$name\"" "$xml" && { why=$(junit_why "$xml" "$name"); break; }
    done
    printf '%s\t%s\n' "$name" "$why"
  done >"$dir/ctest-failed.txt"
fi
echo "ctest: $passed passed, $n_failed failed, $skipped skipped"
[ ${#reruns[@]} = 0 ] || echo "ctest: ${#reruns[@]} of them passed only on a rerun: ${reruns[*]}"
for name in "${final_failed[@]}"; do
  echo "ctest: FAILED $name"
done
[ "$n_failed" = 0 ]
