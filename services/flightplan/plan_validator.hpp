#pragma once
// Validation by expansion: every leg of the expanded stream is checked against every no-fly zone (with its
// buffer), and a goto cycle that produces no waypoints is found. The expander runs over the main element
// list and over each detached block with repeats folded: a goto-free repeat runs two iterations (which show
// every leg it has, the wrap-around leg included) and is then stepped over, so a finite plan is checked
// completely in time proportional to its distinct geometry. Gotos are followed literally, up to `limit`
// waypoints per entry point; a plan that loops through gotos is checked over that prefix. The expander
// checks legs again while streaming.
#include <cstdint>
#include <vector>

#include "services/flightplan/diagnostic.hpp"
#include "services/flightplan/plan.hpp"

namespace airseg::flightplan {

void check_legs(const Plan& plan, std::uint64_t limit, std::vector<Diagnostic>& errors);

}  // namespace airseg::flightplan
