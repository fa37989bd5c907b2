# CMake toolchain file: Debian arm64 (aarch64-linux-gnu) with the Debian cross compiler and a sysroot.
# cmake -DCMAKE_TOOLCHAIN_FILE=packaging/toolchain-arm64.cmake [-DAIRSEG_SYSROOT=DIR] ...
set(AIRSEG_TARGET_ARCH arm64)
set(AIRSEG_TARGET_TRIPLET aarch64-linux-gnu)
set(AIRSEG_TARGET_PROCESSOR aarch64)
set(AIRSEG_QEMU qemu-aarch64)
include(${CMAKE_CURRENT_LIST_DIR}/toolchain-arm-common.cmake)
