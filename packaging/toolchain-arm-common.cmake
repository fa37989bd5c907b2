# Cross-compiling for ARM Debian (armhf, armel, arm64) against a sysroot made by packaging/make-sysroot.sh.
# Included by toolchain-armhf.cmake / toolchain-armel.cmake / toolchain-arm64.cmake, which set
# AIRSEG_TARGET_TRIPLET and AIRSEG_TARGET_ARCH first (arm64 also AIRSEG_TARGET_PROCESSOR and AIRSEG_QEMU).
#
# AIRSEG_SYSROOT (cache variable or environment) names the sysroot; default: sysroots/<arch> at
# the top of the tree if there is one, else the user's cache where packaging/lib.sh keeps them
# (AIRSEG_SYSROOTS, default ~/.cache/airseg/sysroots/<arch>). Test executables run through qemu-arm-static (qemu-aarch64-static) -L <sysroot>.

if(NOT AIRSEG_SYSROOT)
  if(DEFINED ENV{AIRSEG_SYSROOT} AND NOT "$ENV{AIRSEG_SYSROOT}" STREQUAL "")
    set(AIRSEG_SYSROOT "$ENV{AIRSEG_SYSROOT}")
  else()
    # packaging/lib.sh keeps the sysroots in the user's cache (AIRSEG_SYSROOTS); sysroots/ in the tree is
    # still looked at first.
    get_filename_component(AIRSEG_SYSROOT "${CMAKE_CURRENT_LIST_DIR}/../sysroots/${AIRSEG_TARGET_ARCH}" ABSOLUTE)
    if(NOT EXISTS "${AIRSEG_SYSROOT}/usr/include")
      if(DEFINED ENV{AIRSEG_SYSROOTS} AND NOT "$ENV{AIRSEG_SYSROOTS}" STREQUAL "")
        set(AIRSEG_SYSROOT "$ENV{AIRSEG_SYSROOTS}/${AIRSEG_TARGET_ARCH}")
      elseif(DEFINED ENV{XDG_CACHE_HOME} AND NOT "$ENV{XDG_CACHE_HOME}" STREQUAL "")
        set(AIRSEG_SYSROOT "$ENV{XDG_CACHE_HOME}/airseg/sysroots/${AIRSEG_TARGET_ARCH}")
      else()
        set(AIRSEG_SYSROOT "$ENV{HOME}/.cache/airseg/sysroots/${AIRSEG_TARGET_ARCH}")
      endif()
    endif()
  endif()
endif()
if(NOT EXISTS "${AIRSEG_SYSROOT}/usr/include")
  message(FATAL_ERROR "No ${AIRSEG_TARGET_ARCH} sysroot in ${AIRSEG_SYSROOT}: run packaging/ensure-sysroot.sh ${AIRSEG_TARGET_ARCH} ${AIRSEG_SYSROOT}")
endif()
# try_compile() projects re-read this file; pass the sysroot on to them.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES AIRSEG_SYSROOT)

set(CMAKE_SYSTEM_NAME Linux)
if(NOT AIRSEG_TARGET_PROCESSOR)
  set(AIRSEG_TARGET_PROCESSOR arm)
endif()
if(NOT AIRSEG_QEMU)
  set(AIRSEG_QEMU qemu-arm)
endif()
set(CMAKE_SYSTEM_PROCESSOR ${AIRSEG_TARGET_PROCESSOR})
set(CMAKE_LIBRARY_ARCHITECTURE ${AIRSEG_TARGET_TRIPLET})
set(CMAKE_C_COMPILER ${AIRSEG_TARGET_TRIPLET}-gcc)
set(CMAKE_CXX_COMPILER ${AIRSEG_TARGET_TRIPLET}-g++)
set(CMAKE_SYSROOT "${AIRSEG_SYSROOT}")

# GCC notes on every std::vector of a 64-bit-aligned type that GCC 7.1 changed how such arguments
# are passed on ARM; everything here is built by one compiler, so the note says nothing.
set(CMAKE_C_FLAGS_INIT "-Wno-psabi")
set(CMAKE_CXX_FLAGS_INIT "-Wno-psabi")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config reads the sysroot's .pc files and prefixes their paths with the sysroot.
set(PKG_CONFIG_EXECUTABLE /usr/bin/pkg-config CACHE FILEPATH "pkg-config reading the target sysroot")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${AIRSEG_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${AIRSEG_SYSROOT}/usr/lib/${AIRSEG_TARGET_TRIPLET}/pkgconfig:${AIRSEG_SYSROOT}/usr/lib/pkgconfig:${AIRSEG_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")

# 64-bit atomics (and all atomics on armv5te) may be library calls into libatomic; link it only
# where a binary needs it.
set(CMAKE_CXX_STANDARD_LIBRARIES "-Wl,--push-state,--as-needed,-latomic,--pop-state" CACHE STRING "" FORCE)
set(CMAKE_C_STANDARD_LIBRARIES "-Wl,--push-state,--as-needed,-latomic,--pop-state" CACHE STRING "" FORCE)

# ctest (and gtest_discover_tests, which lists the cases by running each test binary) runs ARM
# executables through this emulator. QEMU_LD_PREFIX makes binaries those tests spawn through
# binfmt_misc find the same sysroot; packaging/cross-test.sh sets it.
find_program(AIRSEG_QEMU_PROGRAM ${AIRSEG_QEMU}-static ${AIRSEG_QEMU} REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR "${AIRSEG_QEMU_PROGRAM};-L;${AIRSEG_SYSROOT}")
