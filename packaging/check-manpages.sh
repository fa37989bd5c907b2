#!/bin/bash
# check-manpages.sh BINDIR MANDIR
#
# Fails when a program's --help names an option (--word) or a command (an indented word under
# "Commands:") that its manual page does not mention, so the hand-written pages in
# packaging/man/ cannot silently fall behind the programs.
set -euo pipefail
bindir=$1 mandir=$2
fail=0
for page in "$mandir"/*.[1-8]; do
  prog=$(basename "${page%.*}")
  exe=$(ls "$bindir"/*/"$prog" "$bindir/$prog" 2>/dev/null | head -n1 || true)
  # A page whose program is not built is not installed either.
  [ -n "$exe" ] || { echo "check-manpages: $prog is not built; $page not checked" >&2; continue; }
  help=$("$exe" --help 2>&1 || true)
  text=$(sed -e 's/\\-/-/g' -e 's/\\f[BIRP]//g' "$page")
  words=$( { grep -oE -- '--[a-z][a-z-]*' <<<"$help"
             sed -n '/^Commands:/,/^$/p' <<<"$help" | sed -n 's/^  \([a-z][a-z-]*\).*/\1/p'; } | sort -u)
  for w in $words; do
    grep -qF -- "$w" <<<"$text" || { echo "check-manpages: $prog --help has '$w', $page does not" >&2; fail=1; }
  done
done
exit $fail
