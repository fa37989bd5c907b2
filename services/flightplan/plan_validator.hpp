#pragma once
// Geometric validation of a loaded plan: every leg of the expanded stream against every no-fly zone
// (with its buffer). Runs the expander over the main element list and over each detached block, up to
// `limit` waypoints each: finite plans below the limit are checked completely; an infinite plan (repeat
// forever, goto loops) is checked over its first `limit` waypoints, which covers every leg of any loop
// shorter than limit/2. The expander checks legs again while streaming.
#include <cstdint>
#include <vector>

#include "services/flightplan/diagnostic.hpp"
#include "services/flightplan/plan.hpp"

namespace airseg::flightplan {

void check_legs(const Plan& plan, std::uint64_t limit, std::vector<Diagnostic>& errors);

}  // namespace airseg::flightplan
