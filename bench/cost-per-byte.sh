#!/bin/sh
# The receive and transmit paths' cost per byte under callgrind, so regressions show:
#   - the MAVLink parser (and decode) at 1, 16, 64 and 4096-byte reads (bench/mavlink/callgrind.sh);
#   - the ground-link transport per delivered payload byte (bench/transport/callgrind.sh).
#
#   bench/cost-per-byte.sh [BUILD_DIR] [C_LIBRARY_DIR]
#
# Needs valgrind and, in BUILD_DIR (default build), the targets bench_mavlink_callgrind and bench_transport.
# C_LIBRARY_DIR (or MAVLINK_C_LIBRARY): a c_library_v2 checkout to compare the parser with; its columns are
# skipped without it. Figures and how to read them: docs/performance.md.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build}
"$here/mavlink/callgrind.sh" "$build" ${2:+"$2"}
echo
"$here/transport/callgrind.sh" "$build"
