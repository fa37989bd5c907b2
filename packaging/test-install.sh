#!/bin/bash
# test-install.sh [DIST_DIR [NEXT_DIR]]
#
# Installs, upgrades and removes the amd64 packages in a throwaway Debian 12 chroot (mmdebstrap, discarded
# afterwards); the host is not touched. DIST_DIR (default dist/) holds the airsegd, airseg-client,
# airseg-sim and airseg .debs of one version V. The upgrade goes to NEXT_DIR's packages: the same source
# rebuilt as V+upgradetest1 with one more comment line in the shipped /etc/airseg/airseg.yaml
# (`build-debs.sh --upgrade-build amd64` writes them to dist/upgrade-test/; CI does this), so that dpkg runs
# the real upgrade paths of the maintainer scripts and a changed conffile. Without NEXT_DIR, DIST_DIR's
# packages are repacked as that version instead (quicker by hand; the packaged files are then the same).
#
# systemd does not run in a chroot, so the chroot pretends it does (/run/systemd/system) and
# deb-systemd-invoke is diverted to a log: the checks read which unit actions the maintainer scripts ask
# systemd for (no start at install, try-restart on upgrade, stop on removal). Checked:
# - airseg-client alone: airsegctl, airseg-ground and their manual pages, the hub's unit (not enabled), no
#   daemon, no airsegd unit, no user airseg;
# - all packages: user airseg (in dialout and gpio), the conffile, /etc/airseg/conf.d, the unit enabled and
#   not started, `systemd-analyze verify` clean, `airsegd --check-config` accepts the shipped file with a
#   drop-in, manual pages, the licence and the docs under /usr/share/doc; the ground-link key made at install
#   (64 hexadecimal characters, mode 600, owner airseg) and named by the shipped file;
# - upgrade with a local setting in conf.d: no conffile prompt (dpkg runs without stdin), the new shipped
#   file installed, the drop-in and the key kept, try-restart of airsegd.service and airseg-ground.service asked and
#   no unit stopped before the new files are in place;
# - removal: stop asked, the daemon gone, the conffile kept; purge: the conffile, /var/lib/airseg and
#   /var/log/airseg gone; removing airseg-client asks to stop the hub.
set -euo pipefail
. "$(dirname "$0")/lib.sh"

dist=${1:-$AIRSEG_ROOT/dist}
next_dir=${2:-}
[ "$(id -u)" -eq 0 ] || die "needs root (mmdebstrap chroot)"
ensure_packages mmdebstrap dpkg-dev
mirror=${AIRSEG_MIRROR:-http://deb.debian.org/debian}

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/v1" "$work/v2"
for pkg in airsegd airseg-client airseg-sim; do
  deb=$(ls "$dist/${pkg}"_*_amd64.deb 2>/dev/null | sort -V | tail -n1)
  [ -n "$deb" ] || die "no ${pkg}_*_amd64.deb in $dist (run packaging/build-debs.sh amd64)"
  cp "$deb" "$work/v1/$pkg.deb"
done
deb=$(ls "$dist"/airseg_*_all.deb 2>/dev/null | sort -V | tail -n1)
[ -n "$deb" ] || die "no airseg_*_all.deb in $dist"
cp "$deb" "$work/v1/airseg.deb"

version=$(dpkg-deb --field "$work/v1/airsegd.deb" Version)
next="$version+upgradetest1"
if [ -n "$next_dir" ]; then
  for pkg in airsegd airseg-client airseg-sim airseg; do
    deb=$(ls "$next_dir/${pkg}_${next}"_*.deb 2>/dev/null | head -n1)
    [ -n "$deb" ] || die "no ${pkg}_${next}_*.deb in $next_dir (packaging/build-debs.sh --upgrade-build amd64)"
    cp "$deb" "$work/v2/$pkg.deb"
  done
fi
# Without NEXT_DIR: each package repacked as version V+upgradetest1 (dependencies between them follow).
for f in "$work"/v1/*.deb; do
  [ -z "$next_dir" ] || break
  tree="$work/tree-$(basename "$f" .deb)"
  dpkg-deb -R "$f" "$tree"
  sed -i -e "s/^Version: .*/Version: $next/" -e "s/(= $version)/(= $next)/g" -e "s/(>= $version)/(>= $next)/g" \
    "$tree/DEBIAN/control"
  # A conffile is not in DEBIAN/md5sums (dpkg keeps its checksum in conffiles handling), so it may change.
  if [ -f "$tree/etc/airseg/airseg.yaml" ]; then
    echo "# shipped by $next" >>"$tree/etc/airseg/airseg.yaml"
  fi
  dpkg-deb --root-owner-group -b "$tree" "$work/v2/$(basename "$f")" >/dev/null
done

# The packages' Depends, without versions and without each other, preinstalled so that plain dpkg -i runs.
deps=$(for f in "$work"/v1/*.deb; do dpkg-deb --field "$f" Depends; done | tr ',' '\n' | sed -e 's/(.*)//' \
  -e 's/|.*//' -e 's/ //g' | grep -vxE 'airsegd|airseg-client|airseg-sim|' | sort -u | paste -sd,)

cat >"$work/checks.sh" <<CHECKS
set -u
next='$next'
CHECKS
cat >>"$work/checks.sh" <<'CHECKS'
fail=0
ok()  { echo "  ok: $*"; }
bad() { echo "  FAIL: $*"; fail=1; }
check() { local what=$1; shift; if "$@" >/dev/null 2>&1; then ok "$what"; else bad "$what"; fi; }
invoked() { grep -qx "$1" /tmp/invoked; }
in_group() { id -nG airseg | tr ' ' '\n' | grep -qx "$1"; }
addgroup --quiet --system gpio   # a board whose GPIO chips belong to group gpio
# A chroot has no running systemd: pretend it has, and log what the maintainer scripts ask of it
# ("Failed to connect to bus" is their systemctl daemon-reload finding no systemd, which they allow).
mkdir -p /run/systemd/system
dpkg-divert --quiet --local --no-rename --add /usr/bin/deb-systemd-invoke
printf '#!/bin/sh\necho "$*" >>/tmp/invoked\n' >/usr/bin/deb-systemd-invoke
chmod 755 /usr/bin/deb-systemd-invoke
: >/tmp/invoked
cd /tmp/v1

echo "airseg-client alone (a ground laptop):"
dpkg -i airseg-client.deb </dev/null >/dev/null || bad "dpkg -i airseg-client failed"
check "airsegctl installed" test -x /usr/bin/airsegctl
check "airsegctl(1) installed" test -f /usr/share/man/man1/airsegctl.1.gz
check "airsegctl runs" /usr/bin/airsegctl --version
check "airseg-ground runs" /usr/bin/airseg-ground --version
check "hub unit installed" test -f /lib/systemd/system/airseg-ground.service
check "hub not enabled: it needs its radio set first" \
  test ! -e /etc/systemd/system/multi-user.target.wants/airseg-ground.service
check "no daemon" test ! -e /usr/sbin/airsegd
check "no unit" test ! -e /lib/systemd/system/airsegd.service
check "no user airseg" sh -c '! getent passwd airseg'

echo "every package, version $(dpkg-deb --field airsegd.deb Version):"
dpkg -i airsegd.deb airseg-sim.deb airseg.deb </dev/null >/dev/null || bad "dpkg -i failed"
check "user airseg exists" getent passwd airseg
check "airseg is in dialout" in_group dialout
check "airseg is in gpio" in_group gpio
check "conffile registered" grep -qx /etc/airseg/airseg.yaml /var/lib/dpkg/info/airsegd.conffiles
check "conf.d exists" test -d /etc/airseg/conf.d
check "unit installed" test -f /lib/systemd/system/airsegd.service
check "unit enabled" test -L /etc/systemd/system/multi-user.target.wants/airsegd.service
check "not started at install" sh -c '! grep -q "start" /tmp/invoked'
out=$(systemd-analyze verify /lib/systemd/system/airsegd.service 2>&1)
[ -z "$out" ] && ok "systemd-analyze verify: clean" || bad "systemd-analyze verify: $out"
echo "  $(systemd-analyze security --offline=true --no-pager /lib/systemd/system/airsegd.service | tail -n1)"
grep -q '^LogsDirectory=airseg$' /lib/systemd/system/airsegd.service && ok "unit has LogsDirectory=airseg" \
  || bad "no LogsDirectory=airseg"
check "a ground-link key was made" test -s /etc/airseg/ground.key
[ "$(stat -c '%a %U' /etc/airseg/ground.key)" = "600 airseg" ] && ok "the key is mode 600, owner airseg" \
  || bad "the key is $(stat -c '%a %U' /etc/airseg/ground.key), not 600 airseg"
grep -qxE '[0-9a-f]{64}' /etc/airseg/ground.key && ok "the key is 64 hexadecimal characters" \
  || bad "the key is not 64 hexadecimal characters"
key_sum=$(sha256sum /etc/airseg/ground.key)
check "the shipped configuration uses it" grep -qE '^  key_file: /etc/airseg/ground.key$' /etc/airseg/airseg.yaml
printf 'log_level: debug\n' >/etc/airseg/conf.d/50-local.yaml
check "shipped configuration with a drop-in is valid" /usr/sbin/airsegd --check-config
/usr/sbin/airsegd --check-config 2>&1 | grep -q "conf.d/50-local.yaml" && ok "--check-config names the drop-in" \
  || bad "--check-config does not name the drop-in"
for page in man8/airsegd.8 man1/airsegctl.1 man1/airseg-apmsim.1 man1/airseg-linksim.1 man1/airseg-mavdump.1; do
  check "manual page $page" test -f "/usr/share/man/$page.gz"
done
for pkg in airsegd airseg-client airseg-sim airseg; do
  check "licence in /usr/share/doc/$pkg/copyright" grep -q '^License: Apache-2.0' "/usr/share/doc/$pkg/copyright"
done
check "docs in /usr/share/doc/airsegd" test -f /usr/share/doc/airsegd/operations.md.gz
check "example plans" test -f /usr/share/doc/airseg-client/examples/plans/rover-survey.yaml

echo "upgrade to $next with a local setting in conf.d:"
: >/tmp/invoked
cd /tmp/v2
dpkg -i airsegd.deb airseg-client.deb airseg-sim.deb airseg.deb </dev/null >/tmp/upgrade.log 2>&1 \
  && ok "upgraded without a prompt" || { bad "upgrade failed"; cat /tmp/upgrade.log; }
[ "$(dpkg-query -W -f '${Version}' airsegd)" = "$next" ] && ok "airsegd is $next" || bad "airsegd not upgraded"
check "the new shipped configuration is installed" grep -qx "# shipped by $next" /etc/airseg/airseg.yaml
check "the drop-in is kept" grep -qx 'log_level: debug' /etc/airseg/conf.d/50-local.yaml
[ "$(sha256sum /etc/airseg/ground.key)" = "$key_sum" ] && ok "the upgrade kept the ground-link key" \
  || bad "the upgrade changed the ground-link key"
invoked "try-restart airsegd.service" && ok "upgrade asks systemd to try-restart airsegd.service" \
  || bad "no try-restart on upgrade: $(cat /tmp/invoked)"
invoked "try-restart airseg-ground.service" && ok "upgrade asks systemd to try-restart airseg-ground.service" \
  || bad "no try-restart of the hub on upgrade: $(cat /tmp/invoked)"
grep -q '^stop' /tmp/invoked && bad "the upgrade stopped the daemon before the new files were in place" \
  || ok "no stop during the upgrade"

echo "removal and purge:"
: >/tmp/invoked
dpkg -r airseg airsegd </dev/null >/dev/null || bad "dpkg -r failed"
invoked "stop airsegd.service" && ok "removal asks systemd to stop airsegd.service" \
  || bad "no stop on removal: $(cat /tmp/invoked)"
check "dpkg -r removes the daemon" test ! -e /usr/sbin/airsegd
check "dpkg -r keeps the conffile" test -f /etc/airseg/airseg.yaml
check "the client stays" test -x /usr/bin/airsegctl
mkdir -p /var/lib/airseg /var/log/airseg   # as the unit's StateDirectory and LogsDirectory would have
dpkg -P airsegd </dev/null >/dev/null || bad "dpkg -P failed"
check "dpkg -P removes the conffile" test ! -e /etc/airseg/airseg.yaml
check "dpkg -P removes /var/lib/airseg" test ! -e /var/lib/airseg
check "dpkg -P removes the ground-link key" test ! -e /etc/airseg/ground.key
check "dpkg -P removes /var/log/airseg" test ! -e /var/log/airseg
check "dpkg -P removes the enablement link" test ! -e /etc/systemd/system/multi-user.target.wants/airsegd.service
: >/tmp/invoked
dpkg -r airseg-sim airseg-client </dev/null >/dev/null || bad "dpkg -r airseg-client failed"
invoked "stop airseg-ground.service" && ok "removing airseg-client asks systemd to stop airseg-ground.service" \
  || bad "no stop of the hub on removal: $(cat /tmp/invoked)"
check "dpkg -r removes the hub" test ! -e /usr/bin/airseg-ground
exit $fail
CHECKS

log "installing $version, upgrading to $next ($([ -n "$next_dir" ] && echo rebuilt || echo repacked)) and removing," \
    "in a throwaway chroot (preinstalled: $deps)"
mmdebstrap --quiet --variant=apt --include="systemd,man-db,$deps" \
  --aptopt='Acquire::Retries "3"' \
  --customize-hook="copy-in \"$work/v1\" \"$work/v2\" \"$work/checks.sh\" /tmp" \
  --customize-hook='chroot "$1" sh /tmp/checks.sh' \
  bookworm /dev/null "deb $mirror bookworm main" "deb $mirror bookworm-updates main"
log "install, upgrade, remove and purge checks passed"
