// A translation unit of its own, outside the library's batch: the path differs in every checkout, so only
// this small object differs with it, and the compiler cache serves the batch to a clone anywhere.
#include "ground/map/map_web_source.hpp"

namespace airseg::ground {

const char* map_web_source_dir() {
    return AIRSEG_MAP_WEB_SOURCE;
}

}  // namespace airseg::ground
