#pragma once
// The flight plan model: what the YAML loader produces and the expander walks. Elements form a tree of
// nodes stored in one deque (parents before children); containers (the plan's element list, repeat,
// block) hold child ids. Positions are kept geographic; the local frame position is derived on demand, as is
// an element's path.
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "services/flightplan/geo.hpp"
#include "services/flightplan/scan_pattern.hpp"

namespace airseg::flightplan {

inline constexpr std::uint32_t kNoNode = std::numeric_limits<std::uint32_t>::max();

/// Where an element came from in its source file (1-based; 0 when unknown).
struct SourceMark {
    int line = 0;
    int col = 0;
};

enum class NodeKind : std::uint8_t {
    ElementList,  // the plan's main element list, or the list of detached named blocks
    Waypoint,
    Hold,
    Scan,
    Orbit,
    Speed,
    Repeat,
    Block,
    Goto,
};
const char* to_string(NodeKind kind);

struct OrbitPattern {
    Enu centre;
    double radius = 0.0;
    double turns = 1.0;
    bool clockwise = true;
    std::uint64_t points_per_turn = 8;
    std::uint64_t count() const;
    Enu point(std::uint64_t k) const;
};

/// What few elements have: kept out of line so that a plan written as a long explicit list of waypoints costs
/// little more than its positions (a Node is 40 bytes; most waypoints have no NodeExtra).
struct NodeExtra {
    std::uint32_t node = kNoNode;          // the element it belongs to (Plan::extras is sorted by it)
    std::vector<std::uint32_t> children;   // ElementList, Repeat, Block
    std::string name;                      // optional for every element; goto/reaction target
    std::optional<double> speed;           // Waypoint/Scan/Orbit: leg speed; Speed: the new speed
    std::optional<double> arrival_radius;  // overrides the vehicle profile
    std::optional<double> hold_seconds;    // Hold: empty = until released
    std::optional<ScanPattern> scan;
    std::optional<OrbitPattern> orbit;
    std::optional<std::uint64_t> repeat_count;  // Repeat: empty = forever
    std::string goto_target_name;
    std::uint32_t goto_target = kNoNode;
    /// Containers: waypoints one execution produces; empty when unbounded or when the subtree contains a
    /// goto (its count then depends on where the goto lands). Leaves derive theirs (Plan::count).
    std::optional<std::uint64_t> count;
};

struct Node {
    NodeKind kind = NodeKind::ElementList;
    // Waypoint / Hold / Orbit (a hold without a position holds where the previous waypoint ends).
    bool has_position = false;
    bool has_alt = false;
    bool has_extra = false;  // a NodeExtra exists for it
    std::uint32_t parent = kNoNode;
    SourceMark mark;
    LatLon geo;  // the local position is derived (Plan::local) rather than stored
    double alt_value = 0.0;

    std::optional<double> alt() const { return has_alt ? std::optional<double>(alt_value) : std::nullopt; }
};
// A long explicit list costs about this per element (plus 4 bytes in its parent's children).
static_assert(sizeof(Node) <= 40);

struct VehicleProfile {
    std::string type = "rover";
    double min_spacing = 4.0;     // metres between consecutive generated waypoints
    double arrival_radius = 2.0;  // metres
    double cruise_speed = 2.0;    // m/s
    /// The plan states cruise_speed: waypoints carry it to the autopilot. Without it, legs without a speed of
    /// their own (a speed element or a per-element speed) go at the autopilot's own speed (CRUISE_SPEED).
    bool cruise_speed_given = false;
    /// The speed a waypoint carries until a speed element: 0 means the autopilot's own.
    double commanded_cruise_speed() const { return cruise_speed_given ? cruise_speed : 0.0; }
    static std::optional<VehicleProfile> defaults_for(std::string_view type);
};

struct NoFlyZone {
    std::string name;
    std::vector<LatLon> polygon;
    std::vector<Enu> local;
    double buffer = 0.0;  // metres kept clear around the polygon
    SourceMark mark;
};

enum class ReactionAction : std::uint8_t { Hold, ReturnHome, Continue, GotoBlock };
const char* to_string(ReactionAction action);

struct Reaction {
    ReactionAction action = ReactionAction::Hold;
    std::string target;  // GotoBlock: name of the element to go to
    std::uint32_t target_node = kNoNode;
};

struct Reactions {
    std::optional<Reaction> link_loss;
    double link_loss_seconds = 30.0;
    std::optional<Reaction> low_battery;
    double low_battery_percent = 20.0;
    std::optional<Reaction> geofence;
};

struct Plan {
    std::string name;
    std::string source_file;
    VehicleProfile vehicle;
    LocalFrame frame;
    std::optional<LatLon> home;
    std::vector<NoFlyZone> no_fly;
    std::vector<LatLon> geofence;
    std::vector<Enu> geofence_local;
    Reactions reactions;

    // Deques: no reallocation peak while a long list loads, and references stay valid as elements are added.
    std::deque<Node> nodes;
    std::deque<NodeExtra> extras;         // sorted by NodeExtra::node
    std::uint32_t main_list = kNoNode;    // the plan's elements
    std::uint32_t blocks_list = kNoNode;  // detached named blocks, reached only by goto or a reaction

    /// The element with this name, or kNoNode.
    std::uint32_t find(std::string_view name) const;
    /// "plan.elements[2].repeat.elements[0]", computed from the tree (empty for an unknown id).
    std::string element_path(std::uint32_t id) const;

    /// The out-of-line members of element `id` (an empty NodeExtra when it has none).
    const NodeExtra& extra(std::uint32_t id) const;
    /// The same, created on first use (loader and tests that build plans by hand). Creating one for an id
    /// below the last one created moves later extras (the loader creates them in id order).
    NodeExtra& extra_for(std::uint32_t id);
    const std::vector<std::uint32_t>& children(std::uint32_t id) const { return extra(id).children; }
    /// Position of element `id` in its parent's children (children are in id order).
    std::uint32_t index_in_parent(std::uint32_t id) const;
    const std::string& element_name(std::uint32_t id) const { return extra(id).name; }
    /// Waypoints one execution of element `id` produces; empty when unbounded or when the subtree contains a
    /// goto.
    std::optional<std::uint64_t> count(std::uint32_t id) const;
    /// The element's position in the plan's local frame.
    Enu local(std::uint32_t id) const { return frame.to_local(nodes[id].geo); }
};

}  // namespace airseg::flightplan
