#!/bin/bash
# make-sysroot.sh ARCH [DIR]
#
# Builds a Debian 12 sysroot for ARCH (armhf, armel, arm64) holding the project's -dev packages, for the
# cross compilers (--sysroot), for qemu-arm-static (-L) and for dpkg-shlibdeps (see
# sysroot-dpkg-db.sh). Default DIR: sysroots/ARCH at the top of the tree. Takes about 10 s.
# Set AIRSEG_MIRROR to use another Debian mirror.
set -euo pipefail
. "$(dirname "$0")/lib.sh"

[ $# -ge 1 ] || die "usage: $0 ARCH [DIR]"
arch=$1
arch_triplet "$arch" >/dev/null
dir=${2:-$AIRSEG_SYSROOTS/$arch}
mkdir -p "$(dirname "$dir")"
dir="$(cd "$(dirname "$dir")" && pwd)/$(basename "$dir")"
mirror=${AIRSEG_MIRROR:-http://deb.debian.org/debian}
security=${AIRSEG_SECURITY_MIRROR:-http://deb.debian.org/debian-security}

ensure_packages mmdebstrap dpkg-dev

include=$(IFS=,; echo "libc6-dev,libstdc++-12-dev,${AIRSEG_DEV_PACKAGES[*]}")
hook="$(cd "$(dirname "$0")" && pwd)/sysroot-dpkg-db.sh"

# Some -dev packages link their .so to an absolute path (zlib1g-dev: libz.so -> /lib/<triplet>/libz.so.1),
# which from the host points outside the sysroot: the linker would skip it and link the static archive.
# Every absolute link becomes relative to its place in the sysroot.
relative_symlinks() {
  local root=$1 link target
  while IFS= read -r -d '' link; do
    target=$(readlink "$link")
    case $target in
      /*) ln -sfn "$(realpath -m --relative-to="$(dirname "$link")" "$root$target")" "$link" ;;
    esac
  done < <(find "$root" -type l -print0)
}

attempt() {
  rm -rf "$dir.tmp"
  mmdebstrap --quiet --variant=extract --arch="$arch" --include="$include" \
    --aptopt='Acquire::Retries "3"' --extract-hook="\"$hook\" \"\$1\"" \
    bookworm "$dir.tmp" "$@"
}

# The security suite is tried first so the sysroot matches an up-to-date host; a mirror caught
# in the middle of a sync fails it, and the point-release suites alone are a good sysroot too.
if ! attempt "deb $mirror bookworm main" "deb $mirror bookworm-updates main" \
             "deb $security bookworm-security main"; then
  log "retrying without bookworm-security"
  attempt "deb $mirror bookworm main" "deb $mirror bookworm-updates main" \
    || die "mmdebstrap failed for $arch"
fi
# qemu-arm -L SYSROOT looks up every absolute path in the sysroot first: device nodes there
# (mmdebstrap's /dev) would shadow the host's, and /dev/ptmx would fail with ENODEV.
rm -rf "$dir.tmp/dev" "$dir.tmp/tmp" "$dir.tmp/run" "$dir.tmp/proc" "$dir.tmp/sys"
relative_symlinks "$dir.tmp"
rm -rf "$dir"
mv "$dir.tmp" "$dir"
# The recorded file lists name the directory the sysroot was built in; keep them true.
sed -i "s|^$dir.tmp/|$dir/|" "$dir"/var/lib/dpkg/info/*.list
echo "$arch ${AIRSEG_DEV_PACKAGES[*]}" >"$dir/.airseg-sysroot"
log "sysroot for $arch ready in $dir"
