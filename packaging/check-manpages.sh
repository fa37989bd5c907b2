#!/bin/bash
# check-manpages.sh MANDIR PROGRAM... [--readme README]
#
# Fails when a program's --help names an option (--word) or a command (an indented word under
# "Commands:") that its manual page MANDIR/PROGRAM.[1-8] does not mention, or when a program has no
# page at all, so the hand-written pages in packaging/man/ cannot silently fall behind the programs.
# With --readme, airsegctl's commands must also be named in README's "Running airsegctl" section.
# Run on every amd64 package (check-deb.sh) and by ctest (docs.manpages_match_help).
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 MANDIR PROGRAM... [--readme README]" >&2; exit 2; }
mandir=$1
shift
programs=()
readme=""
while [ $# -gt 0 ]; do
  case "$1" in
    --readme) readme=$2; shift 2 ;;
    *) programs+=("$1"); shift ;;
  esac
done
fail=0
# The words a --help text promises: options anywhere, commands in the "Commands:" block.
help_words() {
  { grep -oE -- '--[a-z][a-z0-9-]*' <<<"$1"
    sed -n '/^Commands:/,/^$/p' <<<"$1" | sed -n 's/^  \([a-z][a-z-]*\).*/\1/p'; } | sort -u
}
for exe in "${programs[@]}"; do
  prog=$(basename "$exe")
  page=$(ls "$mandir/$prog".[1-8] 2>/dev/null | head -n1 || true)
  [ -n "$page" ] || { echo "check-manpages: $prog has no manual page in $mandir" >&2; fail=1; continue; }
  help=$("$exe" --help 2>&1 || true)
  [ -n "$help" ] || { echo "check-manpages: $prog --help printed nothing" >&2; fail=1; continue; }
  text=$(sed -e 's/\\-/-/g' -e 's/\\f[BIRP]//g' "$page")
  for w in $(help_words "$help"); do
    grep -qF -- "$w" <<<"$text" || { echo "check-manpages: $prog --help has '$w', $page does not" >&2; fail=1; }
  done
  if [ -n "$readme" ] && [ "$prog" = airsegctl ]; then
    section=$(sed -n '/^## Running airsegctl/,/^## /p' "$readme")
    for w in $(sed -n '/^Commands:/,/^$/p' <<<"$help" | sed -n 's/^  \([a-z][a-z-]*\).*/\1/p' | sort -u); do
      grep -qF -- "\`$w" <<<"$section" || { echo "check-manpages: airsegctl command '$w' is not in $readme" >&2; fail=1; }
    done
  fi
done
exit $fail
