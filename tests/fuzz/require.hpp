#pragma once
// The fuzz targets' assertion: names the broken property (file and line) before aborting, so a crash report
// says what failed. A macro because clang 14 with libstdc++ 12 has no std::source_location.
#include <cstdio>
#include <cstdlib>

namespace airseg::fuzz {

[[noreturn]] inline void property_broken(const char* file, int line) {
    std::fprintf(stderr, "property broken at %s:%d\n", file, line);
    std::abort();
}

}  // namespace airseg::fuzz

#define require(condition) ((condition) ? void() : ::airseg::fuzz::property_broken(__FILE__, __LINE__))
