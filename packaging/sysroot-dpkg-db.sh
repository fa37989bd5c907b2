#!/bin/bash
# sysroot-dpkg-db.sh ROOT
#
# Records the packages extracted into the sysroot ROOT (by `mmdebstrap --variant=extract`, whose
# .debs are still in ROOT/var/cache/apt/archives) in ROOT/var/lib/dpkg, as if dpkg had installed
# them: a status entry, the file list and the shlibs/symbols files of each package.
#
# Why: dpkg-shlibdeps maps each library an ARM binary needs to the package that ships it
# (dpkg-query --search) and reads that package's symbols file to compute Depends. The extract
# variant installs nothing, so without this record a cross build could not compute its Depends.
# The file lists hold the paths as seen from the build machine (ROOT prefixed), because that is
# where dpkg-shlibdeps finds the libraries (its -l options point into ROOT).
set -euo pipefail

root=$(cd "$1" && pwd)
admin="$root/var/lib/dpkg"
archives="$root/var/cache/apt/archives"
mkdir -p "$admin/info" "$admin/updates"
# Database format 1: info files of Multi-Arch: same packages are named pkg:arch.*
echo 1 >"$admin/info/format"
: >"$admin/status"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

shopt -s nullglob
debs=("$archives"/*.deb)
[ ${#debs[@]} -gt 0 ] || { echo "sysroot-dpkg-db: no .deb in $archives" >&2; exit 1; }

for deb in "${debs[@]}"; do
  rm -rf "$tmp/control"
  dpkg-deb --control "$deb" "$tmp/control"
  pkg=$(dpkg-deb --field "$deb" Package)
  arch=$(dpkg-deb --field "$deb" Architecture)
  multiarch=$(dpkg-deb --field "$deb" Multi-Arch)
  # dpkg names a Multi-Arch: same package's files pkg:arch.*, every other one pkg.*
  name=$pkg
  [ "$multiarch" = same ] && name="$pkg:$arch"

  { echo "Package: $pkg"; echo "Status: install ok installed"
    grep -v '^Package:' "$tmp/control/control"; echo; } >>"$admin/status"

  dpkg-deb --fsys-tarfile "$deb" | tar -t | sed -e 's|^\./|/|' -e 's|/$||' -e '/^$/d' \
    | sed "s|^|$root|" >"$admin/info/$name.list"
  for f in shlibs symbols; do
    if [ -f "$tmp/control/$f" ]; then cp "$tmp/control/$f" "$admin/info/$name.$f"; fi
  done
done
echo "sysroot-dpkg-db: recorded ${#debs[@]} packages in $admin" >&2
