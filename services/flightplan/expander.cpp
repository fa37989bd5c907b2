#include "services/flightplan/expander.hpp"

#include <algorithm>
#include <limits>

namespace airseg::flightplan {

const char* to_string(WaypointAction action) {
    switch (action) {
        case WaypointAction::Go:
            return "go";
        case WaypointAction::HoldFor:
            return "hold";
        case WaypointAction::HoldUntilReleased:
            return "hold-until-released";
    }
    return "?";
}

Expander::Expander(std::shared_ptr<const Plan> plan, bool enforce_no_fly, bool fold_repeats)
    : plan_(std::move(plan)), enforce_no_fly_(enforce_no_fly), fold_repeats_(fold_repeats) {
    for (const auto& zone : plan_->no_fly) {
        zone_boxes_.push_back(Box::around(zone.local, zone.buffer));
    }
    for (std::uint32_t i = 0; i < plan_->nodes.size(); ++i) {
        if (plan_->nodes[i].kind != NodeKind::Repeat) {
            continue;
        }
        std::optional<std::uint64_t> sum = 0;
        for (auto c : plan_->children(i)) {
            const auto cc = plan_->count(c);
            if (!cc) {
                sum.reset();
                break;
            }
            *sum += *cc;
        }
        body_count_.emplace_back(i, sum);
    }
    reset_to_origin();
}

const std::optional<std::uint64_t>& Expander::body_count(std::uint32_t repeat) const {
    static const std::optional<std::uint64_t> kNone;
    auto it = std::lower_bound(body_count_.begin(), body_count_.end(), repeat,
                               [](const auto& entry, std::uint32_t id) { return entry.first < id; });
    return it != body_count_.end() && it->first == repeat ? it->second : kNone;
}

void Expander::reset_to_origin() {
    stack_.clear();
    leaf_ = kNoNode;
    position_ = origin_.index;
    speed_ = plan_->vehicle.commanded_cruise_speed();
    // The first waypoint after a (re)start always carries the speed, so the autopilot gets it set.
    speed_changed_ = true;
    last_position_.reset();
    error_.reset();
    if (origin_.element == StreamOrigin::kStreamStart) {
        if (plan_->main_list != kNoNode) {
            stack_.push_back({plan_->main_list, 0, 0});
        }
    } else {
        place_at(origin_.element);
    }
}

void Expander::place_at(std::uint32_t target) {
    const auto& nodes = plan_->nodes;
    stack_.clear();
    if (nodes[target].kind == NodeKind::ElementList) {
        stack_.push_back({target, 0, 0});
        return;
    }
    std::vector<std::pair<std::uint32_t, std::uint32_t>> chain;  // (ancestor, its child on the way to target)
    std::uint32_t child = target;
    for (std::uint32_t p = nodes[target].parent; p != kNoNode; p = nodes[p].parent) {
        chain.emplace_back(p, child);
        if (nodes[p].kind == NodeKind::ElementList) {
            break;
        }
        child = p;
    }
    std::reverse(chain.begin(), chain.end());
    for (auto [ancestor, on_path] : chain) {
        if (ancestor == plan_->blocks_list) {
            continue;  // a detached block ends the plan when it ends
        }
        const std::uint32_t next = plan_->index_in_parent(on_path) + (on_path == target ? 0 : 1);
        stack_.push_back({ancestor, next, 0});
    }
    if (nodes[target].parent == plan_->blocks_list) {
        stack_.push_back({target, 0, 0});
    }
}

bool Expander::activate_next_leaf(std::uint64_t* skip_budget) {
    const auto& nodes = plan_->nodes;
    const std::size_t step_limit = 4 * nodes.size() + 64;
    std::size_t steps = 0;
    // Seeking: skip whole iterations of a goto-free repeat, keeping the last one to walk so that speed
    // elements inside it still take effect.
    auto fast_forward = [&](Frame& f) {
        const auto& per = body_count(f.node);
        if (skip_budget == nullptr || !per || *per == 0) {
            return;
        }
        const auto& total = plan_->extra(f.node).repeat_count;
        const std::uint64_t left = total ? *total - f.iteration : std::numeric_limits<std::uint64_t>::max();
        const std::uint64_t k = std::min(*skip_budget / *per, left);
        if (k < 2) {
            return;
        }
        f.iteration += k - 1;
        position_ += (k - 1) * *per;
        *skip_budget -= (k - 1) * *per;
        steps = 0;
    };
    while (!stack_.empty()) {
        if (++steps > step_limit) {
            error_ = "the plan loops without producing waypoints (goto cycle)";
            stack_.clear();
            return false;
        }
        Frame& f = stack_.back();
        const Node& container = nodes[f.node];
        if (f.box == nullptr) {
            f.box = &plan_->extra(f.node);
        }
        const NodeExtra& box = *f.box;
        if (f.next_child >= box.children.size()) {
            if (fold_repeats_ && container.kind == NodeKind::Repeat && f.iteration >= 1 &&
                body_count(f.node)) {
                // Iterations are identical: after two, every leg of the repeat has been seen once.
                if (!box.repeat_count) {
                    stack_.clear();
                    return false;
                }
                position_ += (*box.repeat_count - f.iteration - 1) * *body_count(f.node);
                stack_.pop_back();
                continue;
            }
            if (container.kind == NodeKind::Repeat &&
                (!box.repeat_count || f.iteration + 1 < *box.repeat_count)) {
                ++f.iteration;
                f.next_child = 0;
                fast_forward(f);
            } else {
                stack_.pop_back();
            }
            continue;
        }
        const std::uint32_t id = box.children[f.next_child++];
        const Node& n = nodes[id];
        switch (n.kind) {
            case NodeKind::Speed:
                speed_ = plan_->extra(id).speed.value_or(speed_);
                speed_changed_ = true;
                break;
            case NodeKind::Repeat:
            case NodeKind::Block:
                stack_.push_back({id, 0, 0});
                if (n.kind == NodeKind::Repeat) {
                    fast_forward(stack_.back());
                }
                break;
            case NodeKind::Goto:
                place_at(plan_->extra(id).goto_target);
                break;
            case NodeKind::ElementList:
                break;
            case NodeKind::Waypoint:
            case NodeKind::Hold:
            case NodeKind::Scan:
            case NodeKind::Orbit: {
                const std::uint64_t count = plan_->count(id).value_or(0);
                if (count == 0) {
                    break;
                }
                if (skip_budget != nullptr && *skip_budget >= count) {
                    *skip_budget -= count;
                    position_ += count;
                    steps = 0;
                    break;
                }
                activate_leaf(id, 0);
                return true;
            }
        }
    }
    return false;
}

void Expander::activate_leaf(std::uint32_t node, std::uint64_t offset) {
    const Node& n = plan_->nodes[node];
    leaf_ = node;
    leaf_extra_ = &plan_->extra(node);
    leaf_count_ = plan_->count(node).value_or(0);
    leaf_offset_ = offset;
    const auto& scan = leaf_extra_->scan;
    if (n.kind == NodeKind::Scan && scan) {
        scan_line_ = 0;
        scan_line_start_ = 0;
        line_ = scan->line(0);
        while (offset - scan_line_start_ >= line_.count && scan_line_ + 1 < scan->line_count()) {
            scan_line_start_ += line_.count;
            line_ = scan->line(++scan_line_);
        }
    }
}

Waypoint Expander::make_waypoint() {
    const Node& n = plan_->nodes[leaf_];
    const NodeExtra& x = *leaf_extra_;
    Waypoint w;
    w.index = position_;
    w.element = leaf_;
    w.origin = origin_;
    w.alt = n.alt();
    w.speed = x.speed.value_or(speed_);
    w.speed_changed = speed_changed_;
    w.arrival_radius = x.arrival_radius.value_or(plan_->vehicle.arrival_radius);
    w.first_of_element = leaf_offset_ == 0;
    w.last_of_element = leaf_offset_ + 1 == leaf_count_;
    switch (n.kind) {
        case NodeKind::Hold:
            w.action = x.hold_seconds ? WaypointAction::HoldFor : WaypointAction::HoldUntilReleased;
            w.hold_seconds = x.hold_seconds.value_or(0.0);
            w.has_position = n.has_position;
            w.position = n.geo;
            w.local = n.has_position ? plan_->local(leaf_) : Enu{};
            return w;
        case NodeKind::Waypoint:
            w.position = n.geo;
            w.local = plan_->local(leaf_);
            return w;
        case NodeKind::Orbit:
            w.local = x.orbit->point(leaf_offset_);
            break;
        case NodeKind::Scan:
            while (leaf_offset_ - scan_line_start_ >= line_.count) {
                scan_line_start_ += line_.count;
                line_ = x.scan->line(++scan_line_);
            }
            w.local = x.scan->point(scan_line_, line_, leaf_offset_ - scan_line_start_);
            break;
        default:
            break;
    }
    w.position = plan_->frame.to_geo(w.local);
    return w;
}

std::optional<Waypoint> Expander::next() {
    if (error_) {
        return std::nullopt;
    }
    if (leaf_ == kNoNode || leaf_offset_ >= leaf_count_) {
        leaf_ = kNoNode;
        if (!activate_next_leaf(nullptr)) {
            return std::nullopt;
        }
    }
    Waypoint w = make_waypoint();
    if (enforce_no_fly_ && w.has_position && last_position_) {
        for (std::size_t z = 0; z < plan_->no_fly.size(); ++z) {
            const auto& zone = plan_->no_fly[z];
            if (zone_boxes_[z].may_touch(*last_position_, w.local) &&
                segment_violates_zone(*last_position_, w.local, zone.local, zone.buffer)) {
                error_ = "the leg to waypoint " + std::to_string(w.index) + " (" + element_path(w.element) +
                         ") enters no-fly zone '" + zone.name + "'";
                leaf_ = kNoNode;
                stack_.clear();
                return std::nullopt;
            }
        }
    }
    if (w.has_position) {
        last_position_ = w.local;
    }
    ++leaf_offset_;
    ++position_;
    speed_changed_ = false;
    return w;
}

bool Expander::seek(std::uint64_t index) {
    if (index < origin_.index) {
        return false;
    }
    Expander before = *this;  // restored when the index is past the end
    if (!seek_from_here(index)) {
        *this = std::move(before);
        return false;
    }
    return true;
}

bool Expander::seek_from_here(std::uint64_t index) {
    if (index < position_ || error_) {
        reset_to_origin();
    }
    std::uint64_t budget = index - position_;
    last_position_.reset();
    if (leaf_ != kNoNode && leaf_offset_ < leaf_count_) {
        const std::uint64_t available = leaf_count_ - leaf_offset_;
        if (budget < available) {
            activate_leaf(leaf_, leaf_offset_ + budget);
            position_ += budget;
            return true;
        }
        budget -= available;
        position_ += available;
    }
    leaf_ = kNoNode;
    if (!activate_next_leaf(&budget)) {
        return false;
    }
    activate_leaf(leaf_, budget);
    position_ += budget;
    return true;
}

bool Expander::jump_to(std::string_view element_name) {
    const std::uint32_t node = plan_->find(element_name);
    return node != kNoNode && jump_to_node(node);
}

bool Expander::jump_to_node(std::uint32_t node) {
    if (node >= plan_->nodes.size()) {
        return false;
    }
    origin_ = {node, position_};
    reset_to_origin();
    return true;
}

bool Expander::restore(StreamOrigin origin, std::uint64_t index) {
    if (origin.element != StreamOrigin::kStreamStart && origin.element >= plan_->nodes.size()) {
        return false;
    }
    origin_ = origin;
    reset_to_origin();
    return seek(index);
}

std::string Expander::element_path(std::uint32_t element) const {
    return plan_->element_path(element);
}

}  // namespace airseg::flightplan
