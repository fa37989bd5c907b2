# CMake toolchain file: Debian armhf (arm-linux-gnueabihf) with the Debian cross compiler and a sysroot.
# cmake -DCMAKE_TOOLCHAIN_FILE=packaging/toolchain-armhf.cmake [-DAIRSEG_SYSROOT=DIR] ...
set(AIRSEG_TARGET_ARCH armhf)
set(AIRSEG_TARGET_TRIPLET arm-linux-gnueabihf)
include(${CMAKE_CURRENT_LIST_DIR}/toolchain-arm-common.cmake)
