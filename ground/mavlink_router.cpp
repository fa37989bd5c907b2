#include "ground/mavlink_router.hpp"

namespace airseg::ground {

void MavlinkRouter::heard(StationId station, std::uint8_t system, std::uint8_t component) {
    auto& known = senders_[station];
    const auto sender = std::pair{system, component};
    if (known.contains(sender)) {
        return;
    }
    if (known.size() >= kMaxSendersPerStation) {
        ++stats_.senders_refused;
        return;
    }
    known.insert(sender);
}

void MavlinkRouter::forget(StationId station) {
    senders_.erase(station);
}

bool MavlinkRouter::delivers(StationId station, const std::optional<FrameTarget>& target) const {
    if (is_broadcast(target)) {
        return true;
    }
    if (to_airsegd(target)) {
        return false;
    }
    const auto it = senders_.find(station);
    if (it == senders_.end()) {
        return false;
    }
    if (target->component == 0) {
        // Every component of the system: any sender of that system at this station.
        const auto first = it->second.lower_bound({target->system, 0});
        return first != it->second.end() && first->first == target->system;
    }
    return it->second.contains({target->system, target->component});
}

std::vector<StationId> MavlinkRouter::destinations(const std::optional<FrameTarget>& target,
                                                   std::span<const StationId> stations) {
    std::vector<StationId> out;
    if (is_broadcast(target)) {
        ++stats_.broadcast;
        out.assign(stations.begin(), stations.end());
        return out;
    }
    if (to_airsegd(target)) {
        ++stats_.to_airsegd;
        return out;
    }
    for (const auto station : stations) {
        if (delivers(station, target)) {
            out.push_back(station);
        }
    }
    ++(out.empty() ? stats_.unrouted : stats_.routed);
    return out;
}

}  // namespace airseg::ground
