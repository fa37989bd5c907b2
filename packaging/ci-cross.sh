#!/bin/bash
# ci-cross.sh: the cross-build stage of CI, on a fresh Debian 12 amd64 machine (as root).
#
# 1. Installs the tools it needs with apt-get and builds the armhf and armel sysroots.
# 2. Builds the armhf and armel packages; each package build runs the whole test suite under
#    qemu-arm (ctest through the toolchain file's emulator, helpers through binfmt_misc), so the
#    ARM binaries that are tested are the ones that are shipped.
# 3. Builds the amd64 package (its tests are CI's native stage, so they are not run twice).
# 4. Checks each .deb (packaging/check-deb.sh: lintian, Architecture, shlibs Depends, ELF format)
#    and installs the amd64 one in a throwaway chroot (packaging/test-install.sh).
# The .debs are left in dist/. AIRSEG_CI_SKIP_INSTALL_TEST=1 skips step 4's chroot.
set -euo pipefail
. "$(dirname "$0")/lib.sh"

t0=$SECONDS
step() { log "[$((SECONDS - t0)) s] $*"; }

step "installing build tools"
# shellcheck disable=SC2046
ensure_packages "${AIRSEG_NATIVE_TOOLS[@]}" ccache "${AIRSEG_DEV_PACKAGES[@]}" \
  $(cross_tools armhf) $(cross_tools armel)
if enable_arm_binfmt; then
  step "binfmt_misc runs ARM programs through qemu-arm"
else
  step "warning: binfmt_misc is not available; tests spawning ARM helper programs will fail"
fi
for arch in armhf armel; do
  step "sysroot $arch"
  "$AIRSEG_ROOT/packaging/ensure-sysroot.sh" "$arch" "$AIRSEG_SYSROOTS/$arch"
done

for arch in armhf armel; do
  step "cross-building and testing $arch"
  "$AIRSEG_ROOT/packaging/build-debs.sh" "$arch"
done
step "building amd64"
"$AIRSEG_ROOT/packaging/build-debs.sh" --no-check amd64

if [ "${AIRSEG_CI_SKIP_INSTALL_TEST:-0}" != 1 ]; then
  step "install / remove / purge test of the amd64 package"
  "$AIRSEG_ROOT/packaging/test-install.sh"
fi

for deb in "$AIRSEG_ROOT"/dist/airseg_*.deb; do
  echo "== $(basename "$deb")"
  dpkg-deb --info "$deb" | sed -n '/^ Package:/,$p'
done
step "done"
