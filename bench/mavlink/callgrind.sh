#!/bin/sh
# Instructions per byte of the MAVLink receive path under callgrind, at the read sizes a serial port gives
# (1, 16, 64 and 4096 bytes per read), on one minute of ArduPilot telemetry (telemetry_stream.hpp), clean:
#   airseg parse         Parser::push() only
#   airseg parse+decode  and every frame decoded into its typed struct (what the autopilot driver does)
#   reference model      tests/unit/mavlink/reference_parser.hpp, the in-tree model of mavlink_parse_char()
#   C library            c_library_v2: mavlink_parse_char() per byte, then mavlink_msg_*_decode()
# and the instructions per decoded message.
#
#   bench/mavlink/callgrind.sh [BUILD_DIR] [C_LIBRARY_DIR]
#
# BUILD_DIR defaults to build (bench_mavlink_callgrind must be built there). The C library is not part of the
# tree: give its directory (the one with protocol.h; the messages in minimal/, standard/ and common/ as
# published today, or all in common/ as in older checkouts) as the second argument or in MAVLINK_C_LIBRARY;
# without it its columns are skipped. Instruction counts are exact and repeatable.
set -eu

build=${1:-build}
clib=${2:-${MAVLINK_C_LIBRARY:-}}
here=$(cd "$(dirname "$0")" && pwd)
bench=$build/bench/mavlink/bench_mavlink_callgrind
[ -x "$bench" ] || { echo "no $bench: cmake --build $build --target bench_mavlink_callgrind" >&2; exit 1; }
command -v valgrind >/dev/null || { echo "valgrind is not installed" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Instructions collected while running "$@", then the second word of the line the program printed
# ("bytes N ..." or "messages N ...").
measure() {
    valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$work/out" "$@" >"$work/stdout" \
        2>"$work/stderr" || { cat "$work/stderr" >&2; exit 1; }
    ir=$(sed -n 's/^summary: *\([0-9]*\).*/\1/p' "$work/out")
    n=$(awk '{print $2; exit}' "$work/stdout")
    echo "$ir $n"
}
per() {  # instructions / units, two decimals
    awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'
}

# The message headers clib_parse.c decodes, each from the folder the library's layout puts it in: today's
# c_library_v2 spreads them over minimal/ (HEARTBEAT), standard/ (GLOBAL_POSITION_INT) and common/; older
# checkouts (and the single-folder dialects) have all of them in common/. Writes clib_messages.h into $work.
clib_messages() {
    local msg dir found
    : >"$work/clib_messages.h"
    for msg in attitude battery_status global_position_int gps_raw_int heartbeat mission_current \
        nav_controller_output radio_status rc_channels servo_output_raw statustext sys_status system_time vfr_hud; do
        found=
        for dir in minimal standard common; do
            if [ -f "$clib/$dir/mavlink_msg_$msg.h" ]; then
                found=$dir
                break
            fi
        done
        [ -n "$found" ] || { echo "no mavlink_msg_$msg.h in $clib/minimal, standard or common" >&2; return 1; }
        echo "#include \"$found/mavlink_msg_$msg.h\"" >>"$work/clib_messages.h"
    done
}

have_clib=no
if [ -n "$clib" ]; then
    if [ -f "$clib/protocol.h" ]; then
        "$bench" write-stream "$work/stream.bin"
        "$bench" write-crcs "$work/crcs.h"
        clib_messages
        ${CC:-cc} -O2 -g -w -include "$work/crcs.h" -I"$clib" -I"$work" "$here/clib_parse.c" -o "$work/clib_parse"
        have_clib=yes
        echo "C library: $clib ($(sed 's/^#include "\(.*\)\/mavlink_msg_.*/\1/' "$work/clib_messages.h" | sort | uniq -c | awk '{printf "%s%s in %s", (NR > 1 ? ", " : ""), $1, $2}'))"
    else
        echo "no protocol.h in $clib: C library columns skipped" >&2
    fi
else
    echo "C library not given (second argument or MAVLINK_C_LIBRARY): its columns are skipped" >&2
fi

echo "MAVLink receive path, instructions per byte (callgrind), one minute of ArduPilot telemetry, clean"
printf '%-6s %14s %20s %16s' read "airseg parse" "airseg parse+decode" "reference model"
[ $have_clib = yes ] && printf ' %12s %20s %8s' "C lib parse" "C lib parse+decode" ratio
echo
for size in 1 16 64 4096; do
    set -- $(measure "$bench" parse $size);        a_parse=$(per "$1" "$2")
    set -- $(measure "$bench" parse-decode $size); a_full=$(per "$1" "$2")
    set -- $(measure "$bench" reference $size);    r_parse=$(per "$1" "$2")
    printf '%-6s %14s %20s %16s' $size "$a_parse" "$a_full" "$r_parse"
    if [ $have_clib = yes ]; then
        set -- $(measure "$work/clib_parse" "$work/stream.bin" parse $size);        c_parse=$(per "$1" "$2")
        set -- $(measure "$work/clib_parse" "$work/stream.bin" parse-decode $size); c_full=$(per "$1" "$2")
        printf ' %12s %20s %7sx' "$c_parse" "$c_full" "$(per "$a_full" "$c_full")"
    fi
    echo
done

set -- $(measure "$bench" decode)
a_dec=$(per "$1" "$2")
printf 'decode, instructions per message: airseg %s' "$a_dec"
if [ $have_clib = yes ]; then
    set -- $(measure "$work/clib_parse" "$work/stream.bin" decode)
    c_dec=$(per "$1" "$2")
    printf ', C library %s, ratio %sx' "$c_dec" "$(per "$a_dec" "$c_dec")"
fi
echo
