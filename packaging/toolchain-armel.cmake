# CMake toolchain file: Debian armel (arm-linux-gnueabi) with the Debian cross compiler and a sysroot.
# cmake -DCMAKE_TOOLCHAIN_FILE=packaging/toolchain-armel.cmake [-DAIRSEG_SYSROOT=DIR] ...
set(AIRSEG_TARGET_ARCH armel)
set(AIRSEG_TARGET_TRIPLET arm-linux-gnueabi)
include(${CMAKE_CURRENT_LIST_DIR}/toolchain-arm-common.cmake)
