#include "services/flightplan/plan.hpp"

#include <algorithm>
#include <cmath>

namespace airseg::flightplan {

const char* to_string(NodeKind kind) {
    switch (kind) {
        case NodeKind::ElementList:
            return "elements";
        case NodeKind::Waypoint:
            return "waypoint";
        case NodeKind::Hold:
            return "hold";
        case NodeKind::Scan:
            return "scan";
        case NodeKind::Orbit:
            return "orbit";
        case NodeKind::Speed:
            return "speed";
        case NodeKind::Repeat:
            return "repeat";
        case NodeKind::Block:
            return "block";
        case NodeKind::Goto:
            return "goto";
    }
    return "?";
}

const char* to_string(ReactionAction action) {
    switch (action) {
        case ReactionAction::Hold:
            return "hold";
        case ReactionAction::ReturnHome:
            return "return_home";
        case ReactionAction::Continue:
            return "continue";
        case ReactionAction::GotoBlock:
            return "goto";
    }
    return "?";
}

std::uint64_t OrbitPattern::count() const {
    return static_cast<std::uint64_t>(std::llround(turns * static_cast<double>(points_per_turn))) + 1;
}

Enu OrbitPattern::point(std::uint64_t k) const {
    // Starts due north of the centre; bearings grow clockwise.
    const double step = 2.0 * kPi / static_cast<double>(points_per_turn);
    const double bearing = (clockwise ? 1.0 : -1.0) * step * static_cast<double>(k % points_per_turn);
    return {centre.e + radius * std::sin(bearing), centre.n + radius * std::cos(bearing)};
}

std::optional<VehicleProfile> VehicleProfile::defaults_for(std::string_view type) {
    if (type == "rover") {
        return VehicleProfile{"rover", 4.0, 2.0, 2.0};
    }
    if (type == "boat") {
        return VehicleProfile{"boat", 5.0, 3.0, 2.0};
    }
    if (type == "plane") {
        return VehicleProfile{"plane", 100.0, 30.0, 18.0};
    }
    if (type == "copter") {
        return VehicleProfile{"copter", 2.0, 1.0, 5.0};
    }
    return std::nullopt;
}

std::uint32_t Plan::find(std::string_view wanted) const {
    if (wanted.empty()) {
        return kNoNode;
    }
    for (const auto& x : extras) {
        if (x.name == wanted) {
            return x.node;
        }
    }
    return kNoNode;
}

namespace {
template <typename Extras>
auto extra_at(Extras& extras, std::uint32_t id) {
    return std::lower_bound(extras.begin(), extras.end(), id,
                            [](const NodeExtra& x, std::uint32_t wanted) { return x.node < wanted; });
}
NodeExtra extra_of(std::uint32_t id) {
    NodeExtra x;
    x.node = id;
    return x;
}
}  // namespace

const NodeExtra& Plan::extra(std::uint32_t id) const {
    static const NodeExtra kNone;
    if (id >= nodes.size() || !nodes[id].has_extra) {
        return kNone;
    }
    if (!extras.empty() && extras.back().node == id) {
        return extras.back();
    }
    auto it = extra_at(extras, id);
    return it != extras.end() && it->node == id ? *it : kNone;
}

NodeExtra& Plan::extra_for(std::uint32_t id) {
    Node& n = nodes.at(id);
    if (extras.empty() || extras.back().node < id) {
        n.has_extra = true;
        return extras.emplace_back(extra_of(id));
    }
    auto it = extra_at(extras, id);
    if (it != extras.end() && it->node == id) {
        return *it;
    }
    n.has_extra = true;
    return *extras.insert(it, extra_of(id));
}

std::uint32_t Plan::index_in_parent(std::uint32_t id) const {
    const auto& siblings = children(nodes[id].parent);
    return static_cast<std::uint32_t>(std::lower_bound(siblings.begin(), siblings.end(), id) -
                                      siblings.begin());
}

std::optional<std::uint64_t> Plan::count(std::uint32_t id) const {
    const Node& n = nodes[id];
    switch (n.kind) {
        case NodeKind::Waypoint:
        case NodeKind::Hold:
            return 1;
        case NodeKind::Speed:
            return 0;
        case NodeKind::Scan: {
            const auto& scan = extra(id).scan;
            return scan ? scan->total_count() : 0;
        }
        case NodeKind::Orbit: {
            const auto& orbit = extra(id).orbit;
            return orbit ? orbit->count() : 0;
        }
        case NodeKind::Goto:
            return std::nullopt;
        case NodeKind::ElementList:
        case NodeKind::Repeat:
        case NodeKind::Block:
            return extra(id).count;
    }
    return std::nullopt;
}

std::string Plan::element_path(std::uint32_t id) const {
    // Paths are rebuilt from the parent chain rather than stored: a long list would otherwise keep a string
    // per element. Shapes: plan.elements[i], <container>.<kind>.elements[i], plan.blocks[i].elements[j].
    if (id >= nodes.size()) {
        return {};
    }
    if (id == main_list) {
        return "plan.elements";
    }
    if (id == blocks_list) {
        return "plan.blocks";
    }
    const Node& n = nodes[id];
    if (n.parent == kNoNode) {
        return {};
    }
    const std::string index = "[" + std::to_string(index_in_parent(id)) + "]";
    const Node& p = nodes[n.parent];
    if (p.kind == NodeKind::ElementList) {
        return element_path(n.parent) + index;
    }
    if (p.kind == NodeKind::Block && p.parent == blocks_list && blocks_list != kNoNode) {
        return element_path(n.parent) + ".elements" + index;
    }
    return element_path(n.parent) + "." + to_string(p.kind) + ".elements" + index;
}

}  // namespace airseg::flightplan
