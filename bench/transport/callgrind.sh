#!/usr/bin/env bash
# Instructions per delivered payload byte of the ground-link transport, counted by callgrind over exactly the
# calls into the two Transport cores (bench_transport toggles collection around each call), on a simulated
# 57600-baud half-duplex radio pair driven as airsegd drives it.
#
#   bench/transport/callgrind.sh [BUILD_DIR] [-- extra bench_transport arguments]
#   ANNOTATE=1 bench/transport/callgrind.sh build   # also print callgrind_annotate of both ends together
#
# Prints, per scenario: instructions per delivered payload byte in total and per end (each end's instructions
# over the bytes delivered in both directions, so the two add up to the total), instructions per
# poll_transmit call, and instructions per simulated second.
set -euo pipefail

build=${1:-build}
shift || true
[[ "${1:-}" == "--" ]] && shift
bench="$build/bench/transport/bench_transport"
if [[ ! -x "$bench" ]]; then
    echo "no $bench: cmake --build $build --target bench_transport" >&2
    exit 1
fi
command -v valgrind >/dev/null || { echo "valgrind is not installed" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Ir collected in one run that counts the calls `selection` names.
collect() {
    local scenario=$1 selection=$2
    valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$work/$scenario.$selection.out" \
        "$bench" --scenario="$scenario" --measure="$selection" "${@:3}" >"$work/$scenario.$selection.txt" \
        2>"$work/$scenario.$selection.log" || { cat "$work/$scenario.$selection.log" >&2; exit 1; }
    awk '/^(summary|totals):/ {print $2; exit}' "$work/$scenario.$selection.out"
}

field() {
    awk -F= -v k="$2" '$1 == k {print $2}' "$1"
}

for scenario in upload telemetry; do
    a=$(collect "$scenario" a "$@")
    b=$(collect "$scenario" b "$@")
    ptx=$(collect "$scenario" poll_transmit "$@")
    out="$work/$scenario.a.txt"
    bytes=$(($(field "$out" a.delivered_bytes) + $(field "$out" b.delivered_bytes)))
    calls=$(($(field "$out" a.poll_transmit_calls) + $(field "$out" b.poll_transmit_calls)))
    seconds=$(field "$out" seconds)
    echo "== $scenario: $(field "$out" seconds) s simulated, $(field "$out" read_bytes)-byte reads," \
        "keyed=$(field "$out" keyed)"
    echo "delivered payload bytes   $bytes (air->ground $(field "$out" b.delivered_bytes)," \
        "ground->air $(field "$out" a.delivered_bytes))"
    echo "wire bytes                air $(field "$out" a.wire_bytes), ground $(field "$out" b.wire_bytes)"
    echo "wire digests              air $(field "$out" a.wire_digest), ground $(field "$out" b.wire_digest)"
    echo "poll_transmit calls       $calls ($(($(field "$out" a.frames) + $(field "$out" b.frames))) returned a frame)"
    awk -v a="$a" -v b="$b" -v ptx="$ptx" -v bytes="$bytes" -v calls="$calls" -v s="$seconds" 'BEGIN {
        printf "Ir total                  %d (air %d, ground %d)\n", a + b, a, b
        printf "Ir per delivered byte     %.0f (air end %.0f, ground end %.0f)\n", (a + b) / bytes, a / bytes, b / bytes
        printf "Ir per poll_transmit call %.0f\n", ptx / calls
        printf "Ir per simulated second   %.0f\n", (a + b) / s
    }'
    if [[ "${ANNOTATE:-0}" == 1 ]]; then
        collect "$scenario" both "$@" >/dev/null
        callgrind_annotate --inclusive=yes "$work/$scenario.both.out" | head -60
    fi
done
