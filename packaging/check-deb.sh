#!/bin/bash
# check-deb.sh ARCH DEB
#
# Checks a built airseg package: lintian reports no error and no warning that is not overridden
# (debian/airseg.lintian-overrides gives each override's reason), the control fields name the
# right Architecture and a Depends computed from shlibs (libc6 and libstdc++6 at least), the
# conffile and the unit are there, and every program is an ELF file for ARCH with the right
# dynamic loader.
set -euo pipefail
. "$(dirname "$0")/lib.sh"

[ $# -eq 2 ] || die "usage: $0 ARCH DEB"
arch=$1 deb=$2
[ -f "$deb" ] || die "no such file: $deb"
fail=0
bad() { log "FAIL ($arch): $*"; fail=1; }

field() { dpkg-deb --field "$deb" "$1"; }
[ "$(field Architecture)" = "$arch" ] || bad "Architecture is '$(field Architecture)'"
depends=$(field Depends)
has_dep() { tr ',' '\n' <<<"$depends" | sed 's/^ *//' | grep -qF -- "$1"; }
for lib in "libc6 (>= " "libstdc++6 (>= " "adduser" "procps"; do
  has_dep "$lib" || bad "Depends lacks '$lib': $depends"
done

dpkg-deb --ctrl-tarfile "$deb" | tar -xOf - ./conffiles 2>/dev/null | grep -qx /etc/airseg/airseg.yaml \
  || bad "/etc/airseg/airseg.yaml is not a conffile"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
dpkg-deb -x "$deb" "$tmp"
[ -f "$tmp/lib/systemd/system/airsegd.service" ] || bad "no systemd unit in the package"
[ -x "$tmp/usr/sbin/airsegd" ] || bad "no /usr/sbin/airsegd in the package"

case "$arch" in
  amd64) want_elf='ELF 64-bit LSB pie executable, x86-64'; want_ld=/lib64/ld-linux-x86-64.so.2 ;;
  armhf) want_elf='ELF 32-bit LSB pie executable, ARM, EABI5'; want_ld=/lib/ld-linux-armhf.so.3 ;;
  armel) want_elf='ELF 32-bit LSB pie executable, ARM, EABI5'; want_ld=/lib/ld-linux.so.3 ;;
esac
programs=0
for f in "$tmp"/usr/bin/* "$tmp"/usr/sbin/*; do
  [ -f "$f" ] || continue
  programs=$((programs + 1))
  desc=$(file -b "$f")
  [[ "$desc" == "$want_elf"* ]] || bad "$(basename "$f"): $desc"
  [[ "$desc" == *"interpreter $want_ld,"* ]] || bad "$(basename "$f") is not linked against $want_ld: $desc"
done
[ "$programs" -gt 0 ] || bad "no programs in the package"

# The hand-written manual pages must name every option and command the programs' --help names.
if [ "$arch" = "$(dpkg --print-architecture)" ]; then
  "$AIRSEG_ROOT/packaging/check-manpages.sh" "$tmp/usr" "$AIRSEG_ROOT/packaging/man" || bad "manual pages behind --help"
fi

if ! lintian --display-info --fail-on error,warning "$deb" >"$tmp/lintian.txt" 2>&1; then
  bad "lintian:"; cat "$tmp/lintian.txt" >&2
fi
summary=$(grep -c . "$tmp/lintian.txt" || true)

if [ "$fail" = 0 ]; then
  log "ok ($arch): $(basename "$deb"): $programs programs, lintian lines: $summary, Depends: $depends"
fi
exit "$fail"
