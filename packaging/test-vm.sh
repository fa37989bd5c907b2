#!/bin/bash
# test-vm.sh DIST_DIR NEXT_DIR
#
# The amd64 packages installed as users install them, in a Debian 12 virtual machine booted with its own
# systemd: the chroot test (test-install.sh) only sees what the maintainer scripts ask of systemd; here
# systemd runs the unit, its watchdog, its hardening and journald. DIST_DIR holds the airsegd,
# airseg-client, airseg-sim and airseg .debs of one version, NEXT_DIR those of the rebuilt next version
# (build-debs.sh --upgrade-build amd64).
#
# The image is made from Debian's packages only (mmdebstrap: systemd, udev, the kernel and the packages'
# dependencies) and cached by the hash of its inputs under AIRSEG_VM_CACHE (default
# ~/.cache/airseg/vm); each run unpacks it, installs DIST_DIR's packages as dpkg -i does on a vehicle (the key
# is made by the package), adds a drop-in that puts the autopilot on the second UART and the ground link on
# loopback UDP, and boots it under qemu-system-x86_64 with software emulation (TCG: /dev/kvm, where there is
# one, is not relied on). The second UART is a host pty of airseg-apmsim (from DIST_DIR's airseg-sim), so the
# daemon drives a simulated autopilot through a real 8250 driver. packaging/vm-checks.sh runs inside at boot
# and prints each check on the third UART: started at boot, READY and STATUS=, the autopilot ready through the
# hardened unit, the ground-link key (airsegctl without it "not authorised", with it commands), the watchdog
# restart after SIGSTOP, SIGHUP, the upgrade to NEXT_DIR (restart, drop-in and key kept), the stop within
# TimeoutStopSec, the journal and the exposure score.
#
# armhf is not booted: the same checks under qemu-system-arm (virt, Debian's armmp kernel) with the ARM suites
# already under qemu-user beside them would not fit CI's time; docs/operations.md says how to run it by hand.
set -euo pipefail
. "$(dirname "$0")/lib.sh"

[ $# -eq 2 ] || die "usage: test-vm.sh DIST_DIR NEXT_DIR"
dist=$1
next_dir=$2
[ "$(id -u)" -eq 0 ] || die "needs root (the image is unpacked and the packages installed as root)"
ensure_packages mmdebstrap qemu-system-x86 e2fsprogs
mirror=${AIRSEG_MIRROR:-http://deb.debian.org/debian}
cache=${AIRSEG_VM_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/airseg/vm}
timeout_s=${AIRSEG_VM_TIMEOUT:-900}

work=$(mktemp -d)
pids=()
cleanup() {
  local p
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
t0=$SECONDS
step() { log "[$((SECONDS - t0)) s] $*"; }

mkdir -p "$work/debs/v1" "$work/debs/next"
for pkg in airsegd airseg-client airseg-sim; do
  deb=$(ls "$dist/${pkg}"_*_amd64.deb 2>/dev/null | sort -V | tail -n1)
  [ -n "$deb" ] || die "no ${pkg}_*_amd64.deb in $dist"
  cp "$deb" "$work/debs/v1/"
done
cp "$(ls "$dist"/airseg_*_all.deb | sort -V | tail -n1)" "$work/debs/v1/"
cp "$next_dir"/*.deb "$work/debs/next/"
dpkg-deb --field "$(ls "$work"/debs/next/airsegd_*.deb)" Version >"$work/debs/next-version"

# The packages' Depends without versions and without each other, in the image so that plain dpkg -i runs.
deps=$(for f in "$work"/debs/v1/*.deb; do dpkg-deb --field "$f" Depends; done | tr ',' '\n' | sed -e 's/(.*)//' \
  -e 's/|.*//' -e 's/ //g' | grep -vxE 'airsegd|airseg-client|airseg-sim|' | sort -u | paste -sd,)
include="systemd-sysv,udev,dbus,linux-image-amd64,initramfs-tools,procps,kmod,$deps"
# The image's recipe is this script's image section and the package list: a change to either makes a new one.
recipe=$(sed -n '/^# image:begin/,/^# image:end/p' "$0")
hash=$(printf '%s\n%s\n%s\n' "$include" "$mirror" "$recipe" | sha256sum | cut -c1-16)
base="$cache/base-$hash.tar"
mkdir -p "$cache"
# image:begin
if [ ! -f "$base" ]; then
  step "making the image (mmdebstrap: $include)"
  mmdebstrap --quiet --variant=apt --format=tar --include="$include" --aptopt='Acquire::Retries "3"' \
    --customize-hook='echo "/dev/vda / ext4 rw,errors=remount-ro 0 1" >"$1/etc/fstab"' \
    --customize-hook='echo airseg-vm >"$1/etc/hostname"' \
    --customize-hook='chroot "$1" systemctl mask serial-getty@ttyS0.service getty@tty1.service apt-daily.timer apt-daily-upgrade.timer e2scrub_all.timer fstrim.timer' \
    bookworm "$base.tmp" "deb $mirror bookworm main" "deb $mirror bookworm-updates main"
  mv "$base.tmp" "$base"
  find "$cache" -name 'base-*.tar' ! -name "base-$hash.tar" -delete
else
  step "the image from the cache: $base"
fi
# image:end

root="$work/root"
mkdir -p "$root"
tar -C "$root" -xf "$base"
mkdir -p "$root/root/debs"
cp -r "$work/debs/." "$root/root/debs/"
chroot "$root" sh -c 'dpkg -i /root/debs/v1/*.deb </dev/null' >"$work/install.log" 2>&1 \
  || { cat "$work/install.log"; die "dpkg -i in the image failed"; }
step "installed $(ls "$work"/debs/v1 | paste -sd' ') in the image"
cat >"$root/etc/airseg/conf.d/50-vm.yaml" <<'YAML'
# The virtual machine's wiring: the autopilot on the second UART, the ground link on loopback UDP.
autopilot:
  port: /dev/ttyS1
groundlink:
  mode: udp
YAML
cp "$AIRSEG_ROOT/packaging/vm-checks.sh" "$root/root/vm-checks.sh"
cat >"$root/etc/systemd/system/airseg-vm-checks.service" <<'UNIT'
[Unit]
Description=airseg package checks under systemd
After=airsegd.service

[Service]
Type=simple
ExecStart=/bin/bash /root/vm-checks.sh
StandardOutput=file:/dev/ttyS2
StandardError=inherit

[Install]
WantedBy=multi-user.target
UNIT
ln -s /etc/systemd/system/airseg-vm-checks.service "$root/etc/systemd/system/multi-user.target.wants/"
kernel=$(ls "$root"/boot/vmlinuz-* | head -n1)
initrd=$(ls "$root"/boot/initrd.img-* | head -n1)
cp "$kernel" "$work/vmlinuz"
cp "$initrd" "$work/initrd"
size_mb=$(($(du -sm "$root" | cut -f1) + 512))
mke2fs -q -t ext4 -L root -d "$root" "$work/disk.img" "${size_mb}M"
rm -rf "$root"
step "disk image ${size_mb} MB"

# The autopilot: airseg-apmsim from the packages under test, on a host pty that becomes the guest's ttyS1.
dpkg-deb -x "$(ls "$work"/debs/v1/airseg-sim_*.deb)" "$work/sim"
"$work/sim/usr/bin/airseg-apmsim" --link "$work/apm" >"$work/apmsim.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do [ -e "$work/apm" ] && break; sleep 0.1; done
[ -e "$work/apm" ] || { cat "$work/apmsim.log"; die "airseg-apmsim made no pty"; }

: >"$work/checks.log"
step "booting (qemu-system-x86_64, TCG)"
boot=$SECONDS
qemu-system-x86_64 -machine pc -accel tcg,thread=multi -cpu max -smp 2 -m 1024 -display none -monitor none \
  -nic none -no-reboot -kernel "$work/vmlinuz" -initrd "$work/initrd" \
  -append "root=/dev/vda rw console=ttyS0,115200 panic=-1 quiet" \
  -drive "file=$work/disk.img,format=raw,if=virtio" \
  -serial "file:$work/console.log" -serial "$(readlink -f "$work/apm")" -serial "file:$work/checks.log" \
  >"$work/qemu.log" 2>&1 &
qemu=$!
pids+=("$qemu")
shown=0
while kill -0 "$qemu" 2>/dev/null && [ $((SECONDS - boot)) -lt "$timeout_s" ]; do
  # Each check as it comes, so that a slow machine's log shows where the time goes.
  lines=$(wc -l <"$work/checks.log")
  if [ "$lines" -gt "$shown" ]; then
    sed -n "$((shown + 1)),${lines}p" "$work/checks.log" | tr -d '\r' | sed "s/^/  [$((SECONDS - boot)) s] /"
    shown=$lines
  fi
  grep -q 'vm-checks: done' "$work/checks.log" && break
  sleep 1
done
sed -n "$((shown + 1)),\$p" "$work/checks.log" | tr -d '\r' | sed "s/^/  [$((SECONDS - boot)) s] /"
for _ in $(seq 60); do kill -0 "$qemu" 2>/dev/null || break; sleep 1; done
result=$(tr -d '\r' <"$work/checks.log" | sed -n 's/^vm-checks: done, \([0-9]*\) failed$/\1/p')
if [ "$result" != 0 ]; then
  log "the guest's console (last 60 lines):"
  tr -d '\r' <"$work/console.log" | tail -n 60 >&2
  cat "$work/qemu.log" >&2
  [ -n "$result" ] || die "the checks did not finish within ${timeout_s} s of the boot"
  die "$result of the checks in the virtual machine failed"
fi
step "every check in the virtual machine passed ($((SECONDS - boot)) s from boot to power-off)"
