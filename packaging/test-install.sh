#!/bin/bash
# test-install.sh [DEB]
#
# Installs the amd64 package in a throwaway Debian 12 chroot (mmdebstrap, discarded afterwards)
# and checks what the package promises: `dpkg -i` creates the system user airseg (in dialout,
# and in gpio, which the chroot has), installs /etc/airseg/airseg.yaml as a conffile and the
# unit, `systemd-analyze verify` accepts the installed unit, `dpkg -r` keeps the conffile and
# `dpkg -P` removes it. The host is not touched. Default DEB: dist/airseg_*_amd64.deb.
set -euo pipefail
. "$(dirname "$0")/lib.sh"

deb=${1:-$(ls "$AIRSEG_ROOT"/dist/airseg_*_amd64.deb 2>/dev/null | head -n1)}
[ -n "$deb" ] && [ -f "$deb" ] || die "no amd64 .deb (run packaging/build-debs.sh amd64)"
[ "$(id -u)" -eq 0 ] || die "needs root (mmdebstrap chroot)"
ensure_packages mmdebstrap
mirror=${AIRSEG_MIRROR:-http://deb.debian.org/debian}

# The package's Depends, without versions, preinstalled so that plain `dpkg -i` is tested.
deps=$(dpkg-deb --field "$deb" Depends | tr ',' '\n' | sed -e 's/(.*)//' -e 's/|.*//' -e 's/ //g' | paste -sd,)

checks=$(mktemp)
trap 'rm -f "$checks"' EXIT
cat >"$checks" <<'CHECKS'
set -eu
fail=0
ok()  { echo "  ok: $*"; }
bad() { echo "  FAIL: $*"; fail=1; }
addgroup --quiet --system gpio   # a board whose GPIO chips belong to group gpio
dpkg -i /tmp/airseg.deb
getent passwd airseg >/dev/null && ok "user airseg exists" || bad "no user airseg"
id -nG airseg | tr ' ' '\n' | grep -qx dialout && ok "airseg is in dialout" || bad "airseg not in dialout"
id -nG airseg | tr ' ' '\n' | grep -qx gpio && ok "airseg is in gpio" || bad "airseg not in gpio"
grep -qx /etc/airseg/airseg.yaml /var/lib/dpkg/info/airseg.conffiles && ok "conffile registered" || bad "no conffile"
[ -f /etc/airseg/airseg.yaml ] && ok "conffile installed" || bad "conffile missing"
[ -f /lib/systemd/system/airsegd.service ] && ok "unit installed" || bad "unit missing"
[ -L /etc/systemd/system/multi-user.target.wants/airsegd.service ] && ok "unit enabled" || bad "unit not enabled"
if out=$(systemd-analyze verify /lib/systemd/system/airsegd.service 2>&1) && [ -z "$out" ]; then
  ok "systemd-analyze verify: clean"
else
  bad "systemd-analyze verify: $out"
fi
echo "  $(systemd-analyze security --offline=true --no-pager /lib/systemd/system/airsegd.service | tail -n1)"
/usr/sbin/airsegd --check-config --config /etc/airseg/airseg.yaml && ok "shipped configuration is valid" \
  || bad "airsegd --check-config rejects the shipped configuration (exit $?)"
man -w airsegd >/dev/null 2>&1 || [ -f /usr/share/man/man8/airsegd.8.gz ] && ok "man page airsegd(8)" || bad "no airsegd(8)"
echo "# local edit" >>/etc/airseg/airseg.yaml
dpkg -r airseg
[ -f /etc/airseg/airseg.yaml ] && ok "dpkg -r keeps the conffile" || bad "dpkg -r removed the conffile"
[ ! -e /usr/sbin/airsegd ] && ok "dpkg -r removes the daemon" || bad "daemon still there after dpkg -r"
dpkg -P airseg
[ ! -e /etc/airseg/airseg.yaml ] && ok "dpkg -P removes the conffile" || bad "conffile still there after dpkg -P"
[ ! -e /etc/systemd/system/multi-user.target.wants/airsegd.service ] && ok "dpkg -P removes the enablement link" \
  || bad "enablement link left after purge"
exit $fail
CHECKS

log "installing $(basename "$deb") in a throwaway chroot (preinstalled: $deps)"
mmdebstrap --quiet --variant=apt --include="systemd,man-db,$deps" \
  --aptopt='Acquire::Retries "3"' \
  --customize-hook="copy-in \"$deb\" /tmp" \
  --customize-hook="mv \"\$1/tmp/$(basename "$deb")\" \"\$1/tmp/airseg.deb\"" \
  --customize-hook="copy-in \"$checks\" /tmp" \
  --customize-hook="chroot \"\$1\" sh /tmp/$(basename "$checks")" \
  bookworm /dev/null "deb $mirror bookworm main" "deb $mirror bookworm-updates main"
log "install, remove and purge checks passed"
