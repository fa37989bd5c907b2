# Shared helpers for the packaging scripts; sourced, never run.
# shellcheck shell=bash

AIRSEG_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# The sysroots live outside the tree, in this user's cache, so that every clone on the machine (a CI run's
# fresh one included) uses the same ones: made once (packaging/ensure-sysroot.sh remakes one whose package
# list changed, or that is more than a week old), and the same paths in every compile command, which the
# compiler cache needs.
AIRSEG_SYSROOTS=${AIRSEG_SYSROOTS:-${XDG_CACHE_HOME:-$HOME/.cache}/airseg/sysroots}
# Logs, the compiler cache's per-stage statistics and the closing table (tools/ci-lib.sh).
export AIRSEG_CI_LOGS=${AIRSEG_CI_LOGS:-$AIRSEG_ROOT/build-logs}
# shellcheck source=../tools/ci-lib.sh
. "$AIRSEG_ROOT/tools/ci-lib.sh"
airseg_ccache_env "$AIRSEG_ROOT"

log() { printf '%s: %s\n' "$(basename "$0")" "$*" >&2; }
die() { log "error: $*"; exit 1; }

# Every architecture the packages are built for (build-debs.sh without arguments).
# shellcheck disable=SC2034
AIRSEG_ARCHES=(amd64 armhf armel arm64)

# GNU triplet of a Debian architecture this project builds for.
arch_triplet() {
  case "$1" in
    amd64) echo x86_64-linux-gnu ;;
    armhf) echo arm-linux-gnueabihf ;;
    armel) echo arm-linux-gnueabi ;;
    arm64) echo aarch64-linux-gnu ;;
    *) die "unsupported architecture '$1' (expected amd64, armhf, armel or arm64)" ;;
  esac
}

# Installs the named Debian packages that are missing (needs root when any is).
ensure_packages() {
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null | grep -qx installed || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  [ "$(id -u)" -eq 0 ] || die "missing packages (install them as root): ${missing[*]}"
  log "installing: ${missing[*]}"
  if [ -z "${AIRSEG_APT_UPDATED:-}" ]; then
    apt-get update -qq || log "apt-get update reported errors; trying with the lists we have"
    export AIRSEG_APT_UPDATED=1
  fi
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# The -dev packages the project builds against, read from Build-Depends in debian/control so the
# host, every sysroot and the Debian package agree.
# shellcheck disable=SC2034  # used by the scripts that source this file
mapfile -t AIRSEG_DEV_PACKAGES < <(sed -n '/^Build-Depends:/,/^[A-Z][A-Za-z-]*:/p' \
  "$AIRSEG_ROOT/packaging/debian/control" | sed -e 's/^Build-Depends://' \
  | grep -oE '^[[:space:]]*[a-z0-9][a-z0-9.+-]*-dev\b' | sed 's/^[[:space:]]*//' | sort -u)

# Tools to build .debs natively.
# shellcheck disable=SC2034
AIRSEG_NATIVE_TOOLS=(build-essential cmake ninja-build pkgconf debhelper dpkg-dev fakeroot lintian file)

# Tools to cross-build for ARCH and run the results under qemu-user.
cross_tools() {
  case "$1" in
    armhf) echo g++-arm-linux-gnueabihf ;;
    armel) echo g++-arm-linux-gnueabi ;;
    arm64) echo g++-aarch64-linux-gnu ;;
  esac
  echo mmdebstrap qemu-user-static binfmt-support
}

# The qemu-user emulator that runs ARCH's programs: qemu-arm for armhf and armel, qemu-aarch64 for arm64.
qemu_for() {
  case "$1" in
    arm64) echo qemu-aarch64 ;;
    *) echo qemu-arm ;;
  esac
}

# Lets the kernel hand ARCH's ELF files to qemu-user-static, so that a test which spawns a helper
# binary (a simulator) runs it under the emulator too. Returns non-zero when that is impossible
# (no root, no binfmt_misc); tests then run only through CMAKE_CROSSCOMPILING_EMULATOR.
enable_arm_binfmt() {
  local qemu entry
  qemu=$(qemu_for "${1:-armhf}")
  entry=/proc/sys/fs/binfmt_misc/$qemu
  if [ -r "$entry" ] && grep -qx enabled "$entry"; then
    return 0
  fi
  [ "$(id -u)" -eq 0 ] || return 1
  update-binfmts --enable "$qemu" >/dev/null 2>&1 || true
  [ -r "$entry" ] && grep -qx enabled "$entry"
}

ccache_launcher_args() {
  if command -v ccache >/dev/null; then
    echo "-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache"
  fi
}
