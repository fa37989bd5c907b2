#!/bin/bash
# ensure-sysroot.sh ARCH DIR
# Makes the ARCH sysroot in DIR unless one made from the current package list, less than a week ago, is
# already there (the sysroots are shared by every clone on the machine: lib.sh's AIRSEG_SYSROOTS). Two runs
# that need the same sysroot at once make it once: the second waits for the first.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
arch=$1 dir=$2
want="$arch ${AIRSEG_DEV_PACKAGES[*]}"
fresh() {
  [ -f "$dir/.airseg-sysroot" ] && [ "$(cat "$dir/.airseg-sysroot")" = "$want" ] &&
    [ -z "$(find "$dir/.airseg-sysroot" -mtime +7)" ]
}
fresh && exit 0
mkdir -p "$(dirname "$dir")"
exec 9>"$dir.lock"
flock 9
fresh && exit 0
"$(dirname "$0")/make-sysroot.sh" "$arch" "$dir"
