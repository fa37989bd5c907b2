#!/bin/bash
# check-deb.sh ARCH DEB...
#
# Checks the airseg packages built for ARCH (airsegd, airseg-client, airseg-sim, and the transitional
# airseg): lintian reports no error and no warning (debian/airsegd.lintian-overrides gives its one
# override's reason); each package holds what it promises and nothing of the others' (the client has no
# daemon and creates no user); Depends are computed from shlibs (libc6 and libstdc++6 at least); every program is an ELF file
# for ARCH with the right dynamic loader and has its manual page; the licence is in each package's
# copyright. On the build machine's own architecture the programs run, and their --help is checked
# against the manual pages and README (check-manpages.sh).
set -euo pipefail
. "$(dirname "$0")/lib.sh"

[ $# -ge 2 ] || die "usage: $0 ARCH DEB..."
arch=$1
shift
fail=0
bad() { log "FAIL ($arch): $*"; fail=1; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

case "$arch" in
  amd64) want_elf='ELF 64-bit LSB pie executable, x86-64'; want_ld=/lib64/ld-linux-x86-64.so.2 ;;
  arm64) want_elf='ELF 64-bit LSB pie executable, ARM aarch64'; want_ld=/lib/ld-linux-aarch64.so.1 ;;
  armhf) want_elf='ELF 32-bit LSB pie executable, ARM, EABI5'; want_ld=/lib/ld-linux-armhf.so.3 ;;
  armel) want_elf='ELF 32-bit LSB pie executable, ARM, EABI5'; want_ld=/lib/ld-linux.so.3 ;;
  *) die "unknown architecture $arch" ;;
esac

# has PKGDIR PATH...: every PATH is in the extracted package.
has() {
  local dir=$1 p
  shift
  for p in "$@"; do [ -e "$dir$p" ] || bad "$(basename "$dir"): no $p"; done
}
lacks() {
  local dir=$1 p
  shift
  for p in "$@"; do [ ! -e "$dir$p" ] || bad "$(basename "$dir"): must not hold $p"; done
}

seen=()
programs=()
for deb in "$@"; do
  [ -f "$deb" ] || die "no such file: $deb"
  pkg=$(dpkg-deb --field "$deb" Package)
  seen+=("$pkg")
  dir="$tmp/$pkg"
  dpkg-deb -x "$deb" "$dir"
  dpkg-deb -e "$deb" "$dir/DEBIAN"
  field() { dpkg-deb --field "$deb" "$1"; }
  depends=$(field Depends)
  has_dep() { tr ',' '\n' <<<"$depends" | sed 's/^ *//' | grep -qF -- "$1"; }
  want_arch=$arch
  [ "$pkg" = airseg ] && want_arch=all
  [ "$(field Architecture)" = "$want_arch" ] || bad "$pkg: Architecture is '$(field Architecture)'"
  grep -q '^License: Apache-2.0' "$dir/usr/share/doc/$pkg/copyright" 2>/dev/null \
    || bad "$pkg: no Apache-2.0 licence in /usr/share/doc/$pkg/copyright"
  if [ "$pkg" != airseg ]; then
    for lib in "libc6 (>= " "libstdc++6 (>= "; do
      has_dep "$lib" || bad "$pkg: Depends lacks '$lib': $depends"
    done
    [ -e "$dir/usr/share/doc/$pkg/README.md.gz" ] || [ -e "$dir/usr/share/doc/$pkg/README.md" ] \
      || bad "$pkg: no README.md in /usr/share/doc/$pkg"
  fi
  case "$pkg" in
    airsegd)
      for d in adduser procps; do has_dep "$d" || bad "airsegd: Depends lacks $d"; done
      has "$dir" /usr/sbin/airsegd /lib/systemd/system/airsegd.service /etc/airseg/airseg.yaml \
        /etc/airseg/conf.d /usr/share/man/man8/airsegd.8.gz /usr/share/doc/airsegd/operations.md.gz
      lacks "$dir" /usr/bin
      grep -qx /etc/airseg/airseg.yaml "$dir/DEBIAN/conffiles" 2>/dev/null \
        || bad "airsegd: /etc/airseg/airseg.yaml is not a conffile"
      # Maintainer scripts: an upgrade restarts a running daemon, removal stops it.
      grep -q 'deb-systemd-invoke try-restart .*airsegd.service' "$dir/DEBIAN/postinst" \
        || bad "airsegd: postinst does not try-restart airsegd.service on upgrade"
      grep -q 'deb-systemd-invoke stop airsegd.service' "$dir/DEBIAN/prerm" 2>/dev/null \
        || bad "airsegd: prerm does not stop airsegd.service on removal"
      grep -q 'adduser .*--system' "$dir/DEBIAN/postinst" || bad "airsegd: postinst creates no system user"
      ;;
    airseg-client)
      has "$dir" /usr/bin/airsegctl /usr/share/man/man1/airsegctl.1.gz \
        /usr/bin/airseg-ground /usr/share/man/man1/airseg-ground.1.gz /lib/systemd/system/airseg-ground.service \
        /usr/share/doc/airseg-client/examples/plans/rover-survey.yaml /usr/share/airseg/map/index.html \
        /usr/share/airseg/map/map.js /usr/share/airseg/map/map.css
      has_dep libjs-leaflet || bad "airseg-client: Depends lacks libjs-leaflet (the map page)"
      lacks "$dir" /usr/sbin /lib/systemd/system/airsegd.service /etc /usr/bin/airseg-apmsim
      [ ! -e "$dir/DEBIAN/postinst" ] || ! grep -q adduser "$dir/DEBIAN/postinst" \
        || bad "airseg-client: postinst creates a user"
      has_dep adduser && bad "airseg-client: depends on adduser"
      ;;
    airseg-sim)
      for p in airseg-apmsim airseg-linksim airseg-mavdump; do
        has "$dir" "/usr/bin/$p" "/usr/share/man/man1/$p.1.gz"
      done
      lacks "$dir" /usr/sbin /lib/systemd /etc /usr/bin/airsegctl
      ;;
    airseg)
      for d in airsegd airseg-client airseg-sim; do has_dep "$d" || bad "airseg: Depends lacks $d"; done
      ;;
    *) bad "unexpected package $pkg" ;;
  esac
  for f in "$dir"/usr/bin/* "$dir"/usr/sbin/*; do
    [ -f "$f" ] || continue
    programs+=("$f")
    name=$(basename "$f")
    section=1
    [[ "$f" == */sbin/* ]] && section=8
    [ -f "$dir/usr/share/man/man$section/$name.$section.gz" ] || bad "$pkg: $name has no manual page"
    desc=$(file -b "$f")
    [[ "$desc" == "$want_elf"* ]] || bad "$name: $desc"
    [[ "$desc" == *"interpreter $want_ld,"* ]] || bad "$name is not linked against $want_ld: $desc"
  done
done
for want in airsegd airseg-client airseg-sim airseg; do
  [[ " ${seen[*]} " == *" $want "* ]] || bad "package $want was not given"
done
[ "${#programs[@]}" = 6 ] || bad "${#programs[@]} programs in the packages, expected 6"

# The hand-written manual pages must name every option and command the programs' --help names.
if [ "$arch" = "$(dpkg --print-architecture)" ]; then
  "$AIRSEG_ROOT/packaging/check-manpages.sh" "$AIRSEG_ROOT/packaging/man" "${programs[@]}" \
    --readme "$AIRSEG_ROOT/README.md" || bad "manual pages or README behind --help"
fi

if ! lintian --display-info --fail-on error,warning "$@" >"$tmp/lintian.txt" 2>&1; then
  bad "lintian:"; cat "$tmp/lintian.txt" >&2
fi
summary=$(grep -c . "$tmp/lintian.txt" || true)

if [ "$fail" = 0 ]; then
  log "ok ($arch): ${seen[*]}: ${#programs[@]} programs, lintian lines: $summary"
fi
exit "$fail"
