#pragma once
// Where the map's page is in the source tree, for a program run from its build directory.

namespace airseg::ground {

/// The source tree's ground/map/web, as configured.
const char* map_web_source_dir();

}  // namespace airseg::ground
