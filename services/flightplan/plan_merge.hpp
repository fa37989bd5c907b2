#pragma once
// Appending one plan to another, as text: the appended plan's elements go after the running plan's
// elements, its named blocks after the running plan's blocks and its no-fly zones join the running plan's.
// Everything else (name, vehicle, reference, home, geofence, reactions) stays the running plan's. Because
// the running plan's elements and its first coordinate are unchanged, the merged plan expands to exactly
// the same waypoints up to the end of the running plan, so a stream can continue on it.
//
// The merge streams: the running text is read as parser events and written out as it is read, and the
// appended items are copied in where the running plan's lists end, so a long running plan costs about its
// text (the merged text) plus the parser, not a document tree. Anchors and aliases keep their meaning: an
// alias in the appended items to a node outside them (its home, another list's item) is written out as a
// copy of that node. Comments and the original spelling of anchors are not kept, as before.
#include <optional>
#include <string>
#include <string_view>

namespace airseg::flightplan {

struct MergedPlan {
    std::optional<std::string> text;  // the merged YAML, when it could be built
    std::string error;                // otherwise what was wrong
    /// The layout could not be streamed (a running list that gets items given as an alias, the plan given
    /// as an alias, an alias used as a key, an appended item aliasing a node that holds it) and both plans
    /// were merged as whole yaml-cpp documents: same result, the memory of two document trees (about 70
    /// times the text).
    bool whole_tree = false;
};

/// Both texts must already load on their own (the appended one is checked first, for its own file:line).
MergedPlan append_plan_text(std::string_view running, std::string_view appended);
/// The same merge with both plans loaded as whole yaml-cpp documents: what append_plan_text falls back to
/// for the layouts above, and the reference its tests compare it with. About 70 times the text in memory.
MergedPlan append_plan_text_as_trees(std::string_view running, std::string_view appended);

}  // namespace airseg::flightplan
