#!/usr/bin/env bash
# Runs clang-tidy with the tree's .clang-tidy (braces and naming) on the C++ sources that changed since the
# whole tree was last checked, or on every source with --all. Any finding fails.
#
#   tools/clang-tidy-check.sh [--all] [--base REV] [BUILD_DIR]
#
# BUILD_DIR (default build-tidy) is configured, not built: clang-tidy needs only its compile_commands.json,
# file by file (AIRSEG_UNITY_BUILD=OFF) and with clang's flags. The tree has no generated sources.
#
# "Changed" means changed since the last commit that touched .clang-tidy: the whole tree passed --all when
# that commit was made. After changing the checks, run --all, fix what it finds, and commit both together.
# --base REV compares with another revision instead. A shallow clone without that commit checks everything.
set -euo pipefail
cd "$(dirname "$0")/.."

all=0
base=""
build=build-tidy
while [ $# -gt 0 ]; do
  case "$1" in
    --all) all=1 ;;
    --base) base=${2:?--base needs a revision}; shift ;;
    -h|--help)
      sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'
      exit 0 ;;
    -*) echo "clang-tidy-check: unknown option '$1' (see --help)" >&2; exit 2 ;;
    *) build=$1 ;;
  esac
  shift
done

tidy=$(command -v clang-tidy || command -v clang-tidy-14 || true)
[ -n "$tidy" ] || { echo "clang-tidy-check: clang-tidy is not installed (apt-get install clang-tidy)" >&2; exit 2; }

if [ "$all" = 0 ] && [ -z "$base" ]; then
  base=$(git log -1 --format=%H -- .clang-tidy 2>/dev/null || true)
  if [ -z "$base" ] || ! git cat-file -e "$base^{commit}" 2>/dev/null; then
    echo "clang-tidy-check: no commit of .clang-tidy in this clone: checking every source"
    all=1
  fi
fi

launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja "${launcher[@]}" -DAIRSEG_UNITY_BUILD=OFF \
  -DAIRSEG_BUILD_TESTS=ON -DAIRSEG_BUILD_BENCH=ON -DAIRSEG_BUILD_FUZZ=OFF >/dev/null

# Every translation unit of the tree, from the compile database.
mapfile -t units < <(python3 - "$build/compile_commands.json" "$PWD" <<'EOF'
import json, os, sys
root = sys.argv[2] + os.sep
for f in sorted({os.path.normpath(e["file"]) for e in json.load(open(sys.argv[1]))}):
    if f.startswith(root) and "/build" not in f[len(root):].split(os.sep)[0]:
        print(f[len(root):])
EOF
)

if [ "$all" = 1 ]; then
  files=("${units[@]}")
  what="every source"
else
  # A changed header is checked through the sources next to it (same name, .cpp), and through every
  # translation unit that includes it when it has none.
  mapfile -t changed < <(git diff --name-only --diff-filter=d "$base" HEAD -- '*.cpp' '*.hpp' '*.h')
  declare -A pick=()
  for f in "${changed[@]}"; do
    case "$f" in
      *.cpp) pick[$f]=1 ;;
      *)
        stem=${f%.*}
        if [ -f "$stem.cpp" ]; then
          pick[$stem.cpp]=1
        else
          while IFS= read -r u; do pick[$u]=1; done < <(grep -lF "\"$f\"" "${units[@]}" || true)
        fi ;;
    esac
  done
  files=()
  for u in "${units[@]}"; do
    [ -n "${pick[$u]:-}" ] && files+=("$u")
  done
  what="sources changed since ${base:0:12}"
fi

echo "clang-tidy-check: ${#files[@]} files ($what)"
[ ${#files[@]} -gt 0 ] || exit 0
log=$build/clang-tidy.log
# One process per core; a finding in a header is reported once per unit that includes it.
# The dialect table's layout is computed at compile time: GCC's constexpr budget covers it, clang's default
# step limit does not.
printf '%s\n' "${files[@]}" | xargs -P "$(nproc)" -n 4 "$tidy" -p "$build" --quiet \
  --extra-arg=-fconstexpr-steps=200000000 >"$log" 2>&1 || true
if grep -q ': \(warning\|error\): ' "$log"; then
  grep -A3 ': \(warning\|error\): ' "$log" | awk '!seen[$0]++' | head -n 200
  echo "clang-tidy-check: findings above ($(grep -c ': \(warning\|error\): ' "$log") in all, full log $log)" >&2
  exit 1
fi
echo "clang-tidy-check: no findings"
