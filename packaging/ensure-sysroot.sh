#!/bin/bash
# ensure-sysroot.sh ARCH DIR
# Makes the ARCH sysroot in DIR unless one made from the current package list is already there.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
arch=$1 dir=$2
want="$arch ${AIRSEG_DEV_PACKAGES[*]}"
if [ -f "$dir/.airseg-sysroot" ] && [ "$(cat "$dir/.airseg-sysroot")" = "$want" ]; then
  exit 0
fi
"$(dirname "$0")/make-sysroot.sh" "$arch" "$dir"
