#include "services/flightplan/plan_validator.hpp"

#include <memory>
#include <set>

#include "services/flightplan/expander.hpp"

namespace airseg::flightplan {

namespace {
constexpr std::size_t kMaxLegErrors = 50;

bool point_violates(Enu p, const NoFlyZone& zone) {
    return point_in_polygon(p, zone.local) || distance_to_boundary(p, zone.local) < zone.buffer;
}
}  // namespace

void check_legs(const Plan& plan, std::uint64_t limit, std::vector<Diagnostic>& errors) {
    // The expander shares ownership; this plan outlives the call, so an aliasing, non-owning pointer is fine.
    std::shared_ptr<const Plan> view(std::shared_ptr<const Plan>{}, &plan);
    std::vector<std::uint32_t> entries;
    entries.push_back(kNoNode);
    if (plan.blocks_list != kNoNode) {
        for (auto b : plan.children(plan.blocks_list)) {
            entries.push_back(b);
        }
    }
    std::vector<Box> boxes;
    for (const auto& zone : plan.no_fly) {
        boxes.push_back(Box::around(zone.local, zone.buffer));
    }
    std::set<std::pair<std::uint32_t, std::size_t>> reported;  // (element, zone)
    for (auto entry : entries) {
        Expander stream(view, /*enforce_no_fly=*/false, /*fold_repeats=*/true);
        if (entry != kNoNode) {
            stream.jump_to_node(entry);
        }
        std::optional<Enu> last;
        for (std::uint64_t n = 0; n < limit; ++n) {
            auto w = stream.next();
            if (!w) {
                break;
            }
            if (!w->has_position) {
                continue;
            }
            for (std::size_t z = 0; z < plan.no_fly.size(); ++z) {
                const auto& zone = plan.no_fly[z];
                const Enu from = last.value_or(w->local);
                const bool bad = boxes[z].may_touch(from, w->local) &&
                                 (last ? segment_violates_zone(*last, w->local, zone.local, zone.buffer)
                                       : point_violates(w->local, zone));
                if (!bad || !reported.emplace(w->element, z).second) {
                    continue;
                }
                const Node& node = plan.nodes[w->element];
                errors.push_back(
                    {plan.source_file, node.mark.line, node.mark.col, plan.element_path(w->element),
                     "the leg to waypoint " + std::to_string(w->index) + " crosses no-fly zone '" +
                         zone.name + "' (buffer " + std::to_string(zone.buffer) + " m)"});
                if (errors.size() >= kMaxLegErrors) {
                    return;
                }
            }
            last = w->local;
        }
        if (auto e = stream.error()) {
            const std::uint32_t at = entry == kNoNode ? plan.main_list : entry;
            const Node& node = plan.nodes[at];
            errors.push_back({plan.source_file, node.mark.line, node.mark.col, plan.element_path(at), *e});
        }
    }
}

}  // namespace airseg::flightplan
