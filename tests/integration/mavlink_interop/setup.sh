#!/bin/sh
# Installs the independent MAVLink implementation (node-mavlink, pinned by package-lock.json) that the
# mavlink_interop test checks airseg-mavdump against, into BUILD_DIR/mavlink_interop. Run once per build
# directory, before ctest; the test itself installs nothing.
#   tests/integration/mavlink_interop/setup.sh BUILD_DIR
set -eu
if [ $# -ne 1 ]; then
    echo "usage: $0 BUILD_DIR" >&2
    exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
dest="$1/mavlink_interop"
mkdir -p "$dest"
cp "$here/package.json" "$here/package-lock.json" "$dest/"
cd "$dest"
npm ci --ignore-scripts --no-audit --no-fund --loglevel=error
echo "node-mavlink installed in $dest/node_modules"
