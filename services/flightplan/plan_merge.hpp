#pragma once
// Appending one plan to another, as text: the appended plan's elements go after the running plan's
// elements, its named blocks after the running plan's blocks and its no-fly zones join the running plan's.
// Everything else (name, vehicle, reference, home, geofence, reactions) stays the running plan's. Because
// the running plan's elements and its first coordinate are unchanged, the merged plan expands to exactly
// the same waypoints up to the end of the running plan, so a stream can continue on it.
#include <optional>
#include <string>
#include <string_view>

namespace airseg::flightplan {

struct MergedPlan {
    std::optional<std::string> text;  // the merged YAML, when it could be built
    std::string error;                // otherwise what was wrong
};

/// Both texts must already load on their own (the appended one is checked first, for its own file:line).
MergedPlan append_plan_text(std::string_view running, std::string_view appended);

}  // namespace airseg::flightplan
