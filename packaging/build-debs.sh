#!/bin/bash
# build-debs.sh [--no-check] [--no-debug-info] [--clean] [--upgrade-build] [ARCH...]
#
# Builds the airseg .debs (airsegd, airseg-client, airseg-sim, and the transitional airseg) for each
# ARCH (default: every one, amd64 armhf armel arm64) on Debian 12 from Debian packages only, and writes
# them to dist/. amd64 is built natively; armhf, armel and arm64 are cross-built with the
# Debian cross compilers against a sysroot (packaging/make-sysroot.sh), without multiarch:
# `dpkg-buildpackage -a ARCH -d` with AIRSEG_SYSROOT pointing at the sysroot.
#
# The tests run during each build (under qemu-arm or qemu-aarch64 for ARM) unless --no-check is given. Each
# architecture's packages are checked afterwards (packaging/check-deb.sh: lintian, contents, fields,
# ELF format, and on amd64 the manual pages against each program's --help).
# --no-debug-info compiles with -g0 and makes no -dbgsym package: about a quarter less compile time
# for CI, and the same machine code (GCC's -g never changes the generated code).
# Work directories: build-pkg-ARCH/. AIRSEG_SOURCE_DIR packages another tree. Missing build tools
# are installed with apt-get (as root). AIRSEG_INTEROP_MODULES: a node_modules directory filled by
# tests/integration/mavlink_interop/setup.sh, so that mavlink_interop runs too (no network here).
# AIRSEG_CTEST_ARGS: more ctest options. The suite runs through tools/run-ctest.sh: every case once, a failure
# fails the build (no case is rerun unless tests/ci-rerun.txt names it with its cause; each rerun is printed).
# AIRSEG_EXTRA_CMAKE_ARGS: more cmake options (CI: -DAIRSEG_TEST_HANG_INJECTION=ON, so that the
# stuck-service test runs on ARM too; packages to ship leave the test-only hook out).
# AIRSEG_GCC_FLAGS: more compiler flags that leave the objects as they are (CI: GCC's garbage collector
# parameters, tools/build-and-test.sh).
# AIRSEG_TEST_JOBS: test cases run at once (default: AIRSEG_JOBS, the build's parallel level).
# --upgrade-build: build the same source again, as version V+upgradetest1 (a changelog entry on top) with one
# comment line more in the shipped airseg.yaml, into dist/upgrade-test/, for packaging/test-install.sh's
# upgrade. Run it after a plain build of that ARCH with the same options: the build directory is reused, so
# only the packaging runs again.
set -euo pipefail
. "$(dirname "$0")/lib.sh"

check=1
clean=0
debug_info=1
upgrade_build=0
arches=()
for a in "$@"; do
  case "$a" in
    --no-check) check=0 ;;
    --no-debug-info) debug_info=0 ;;
    --clean) clean=1 ;;
    --upgrade-build) upgrade_build=1 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    -*) die "unknown option $a" ;;
    *) arch_triplet "$a" >/dev/null; arches+=("$a") ;;
  esac
done
[ ${#arches[@]} -gt 0 ] || arches=("${AIRSEG_ARCHES[@]}")

build_arch=$(dpkg --print-architecture)
[ "$build_arch" = amd64 ] || die "this script builds on amd64 (this machine is $build_arch)"

version=$(dpkg-parsechangelog -l "$AIRSEG_ROOT/packaging/debian/changelog" -S Version)
upstream=$(sed -n 's/^project(airseg VERSION \([0-9.]*\).*/\1/p' "$AIRSEG_ROOT/CMakeLists.txt")
[ "${version%%-*}" = "$upstream" ] \
  || log "warning: debian/changelog says $version but CMakeLists.txt says $upstream"

# The tree to package: this one, or AIRSEG_SOURCE_DIR (e.g. an export of a commit).
source_tree=${AIRSEG_SOURCE_DIR:-$AIRSEG_ROOT}
ensure_packages "${AIRSEG_NATIVE_TOOLS[@]}" ccache
mkdir -p "$AIRSEG_ROOT/dist"

# Copies the source tree into DIR with debian/ at its top, keeping DIR's build directory
# (obj-*) so that a rebuild is incremental unless --clean is given.
stage_source() {
  local dir=$1
  mkdir -p "$dir"
  find "$dir" -mindepth 1 -maxdepth 1 ! -name 'obj-*' -exec rm -rf {} +
  if [ "$clean" = 1 ]; then rm -rf "$dir"/obj-*; fi
  # The top-level entries by name, never the top directory itself: the builds of the other architectures
  # beside this one create their build-pkg-ARCH/ and dist/ in it, and tar fails ("file changed as we read it")
  # on a directory that changes while it is archived.
  local -a entries=()
  local entry name
  for entry in "$source_tree"/* "$source_tree"/.[!.]*; do
    [ -e "$entry" ] || continue
    name=${entry##*/}
    case "$name" in .git | build* | dist | sysroots | .cache) continue ;; esac
    entries+=("$name")
  done
  tar -C "$source_tree" -cf - -- "${entries[@]}" | tar -C "$dir" -xf -
  cp -a "$source_tree/packaging/debian" "$dir/debian"
}

build_one() {
  local arch=$1 work="$AIRSEG_ROOT/build-pkg-$1" src opts sysroot="" pkg_version=$version
  src="$work/airseg-$version"
  [ "$upgrade_build" = 0 ] || pkg_version="$version+upgradetest1"
  local -a dpkg_args=(-b -us -uc --no-sign)
  # debian/ is fresh on every run, so skipping the pre-clean only keeps the cmake build directory.
  [ "$clean" = 1 ] || dpkg_args+=(--no-pre-clean)
  opts="parallel=${AIRSEG_JOBS:-2} terse"
  [ "$check" = 1 ] || opts="$opts nocheck"
  local -a env=()
  local gcc_flags=${AIRSEG_GCC_FLAGS:-}
  [ "$debug_info" = 1 ] || { opts="$opts noautodbgsym"; gcc_flags="-g0${gcc_flags:+ $gcc_flags}"; }
  [ -z "$gcc_flags" ] || env+=(DEB_CFLAGS_APPEND="$gcc_flags" DEB_CXXFLAGS_APPEND="$gcc_flags")

  if [ "$arch" = amd64 ]; then
    ensure_packages "${AIRSEG_DEV_PACKAGES[@]}"
  else
    # shellcheck disable=SC2046
    ensure_packages $(cross_tools "$arch")
    sysroot="$AIRSEG_SYSROOTS/$arch"
    "$AIRSEG_ROOT/packaging/ensure-sysroot.sh" "$arch" "$sysroot"
    if [ "$check" = 1 ] && ! enable_arm_binfmt "$arch"; then
      log "warning: binfmt_misc for $(qemu_for "$arch") is not available; tests that spawn helper programs may fail"
    fi
    dpkg_args+=(-a "$arch" -d)
    # The tests do run: ctest through qemu-user, helper programs through binfmt_misc.
    [ "$check" = 0 ] || opts="$opts crossbuildcanrunhostbinaries"
    # dpkg-architecture checks that CC builds for the host architecture.
    env+=(CC="$(arch_triplet "$arch")-gcc" CXX="$(arch_triplet "$arch")-g++")
  fi

  log "building airseg $pkg_version for $arch in $work"
  stage_source "$src"
  if [ "$upgrade_build" = 1 ]; then
    local entry
    entry=$(printf 'airseg (%s) bookworm; urgency=medium\n\n  * The same source rebuilt, for the upgrade test.\n\n -- %s  %s\n' \
      "$pkg_version" "$(dpkg-parsechangelog -l "$src/debian/changelog" -S Maintainer)" "$(date -R)")
    printf '%s\n\n%s\n' "$entry" "$(cat "$src/debian/changelog")" >"$src/debian/changelog"
    echo "# shipped by $pkg_version" >>"$src/config/airseg.yaml"
  fi
  # CMake reads the compiler flags only when it creates a build directory: one kept from a build
  # with other options (tests, debug information, compiler flags) is started afresh.
  local obj="$src/obj-$(arch_triplet "$arch")" key="check=$check debug_info=$debug_info${AIRSEG_EXTRA_CMAKE_ARGS:+ $AIRSEG_EXTRA_CMAKE_ARGS}${gcc_flags:+ flags=$gcc_flags}"
  if [ -d "$obj" ] && [ "$(cat "$obj/.airseg-build-options" 2>/dev/null)" != "$key" ]; then
    rm -rf "$obj"
  fi
  rm -f "$work"/*.deb "$work"/*.ddeb "$work"/*.buildinfo "$work"/*.changes
  local start=$SECONDS
  # debhelper gives the build a HOME of its own inside debian/: lib.sh has exported the compiler cache's
  # directory and base (tools/ci-lib.sh), so the package builds share the cache of every other build here.
  (cd "$src" && env "${env[@]}" AIRSEG_SYSROOT="$sysroot" DEB_BUILD_OPTIONS="$opts" \
     AIRSEG_CMAKE_ARGS="$(ccache_launcher_args) ${AIRSEG_EXTRA_CMAKE_ARGS:-}" AIRSEG_CTEST_ARGS="${AIRSEG_CTEST_ARGS:-}" \
     dpkg-buildpackage "${dpkg_args[@]}") \
     >"$work/build.log" 2>&1 || { tail -n 60 "$work/build.log"; die "build for $arch failed (log: $work/build.log)"; }
  echo "$key" >"$obj/.airseg-build-options"
  log "built $arch in $((SECONDS - start)) s (log: $work/build.log)"
  log "$arch: $(grep -cE '^[^ :]+:[0-9]+:[0-9]+: warning: ' "$work/build.log" || true) compiler warnings"
  if [ "$check" = 1 ]; then
    # ctest's closing lines, for whoever reads this output.
    grep -E '^[0-9]+% tests passed|^Total Test time' "$work/build.log" | sed "s/^/$arch: /" || true
  fi
  # The packages to install in dist/, debug symbols (for crash analysis on the vehicle) apart in dist/debug/.
  if [ "$upgrade_build" = 1 ]; then
    rm -rf "$AIRSEG_ROOT/dist/upgrade-test" && mkdir -p "$AIRSEG_ROOT/dist/upgrade-test"
    cp "$work"/*_"$pkg_version"_"$arch".deb "$work"/*_"$pkg_version"_all.deb "$AIRSEG_ROOT/dist/upgrade-test/"
    log "$arch: version $pkg_version in dist/upgrade-test/"
    return
  fi
  mkdir -p "$AIRSEG_ROOT/dist/debug"
  local -a debs=()
  local deb
  rm -f "$AIRSEG_ROOT"/dist/debug/*-dbgsym_*_"$arch".*deb
  for deb in "$work"/*_"$version"_"$arch".*deb "$work"/*_"$version"_all.deb; do
    [ -f "$deb" ] || continue
    case "$deb" in
      *-dbgsym_*) cp "$deb" "$AIRSEG_ROOT/dist/debug/" ;;
      *) rm -f "$AIRSEG_ROOT"/dist/"$(basename "${deb%%_*}")"_*_"$arch".deb
         # Copied whole, then renamed: the builds of other architectures beside this one copy the same
         # architecture-independent package, and check it, at any moment.
         cp "$deb" "$AIRSEG_ROOT/dist/.$(basename "$deb").$$"
         mv -f "$AIRSEG_ROOT/dist/.$(basename "$deb").$$" "$AIRSEG_ROOT/dist/$(basename "$deb")"
         debs+=("$AIRSEG_ROOT/dist/$(basename "$deb")") ;;
    esac
  done
  "$AIRSEG_ROOT/packaging/check-deb.sh" "$arch" "${debs[@]}"
}

[ "$upgrade_build" = 0 ] || [ ${#arches[@]} = 1 ] || die "--upgrade-build builds one architecture"
for arch in "${arches[@]}"; do
  build_one "$arch"
done
ls -l "$AIRSEG_ROOT"/dist/
