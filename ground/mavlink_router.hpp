#pragma once
// MavlinkRouter: which ground stations get a frame from the vehicle, by the rule of mavlink-router. Each
// station (a UDP peer, a TCP client) is known by the systems and components it sends as; a frame addressed
// to a system (and component) goes only to the stations where that system (component) has been heard; a
// frame without an addressee, or addressed to system 0, goes to all; a frame addressed to airsegd itself (its
// system and component with the autopilot, 255/191) goes to none. Sans-IO: station ids and frames in,
// station ids out.
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <vector>

#include "services/autopilot/mavlink/target.hpp"

namespace airseg::ground {

using mavlink::frame_target;
using mavlink::FrameTarget;
using mavlink::target_offsets;
using StationId = std::uint64_t;

struct MavlinkRouterStats {
    std::uint64_t broadcast = 0;        // frames without an addressee (or to system 0): every station
    std::uint64_t routed = 0;           // addressed frames that went to at least one station
    std::uint64_t unrouted = 0;         // addressed frames no station had heard the addressee of
    std::uint64_t to_airsegd = 0;       // frames addressed to airsegd itself, kept from every station
    std::uint64_t senders_refused = 0;  // (system, component) pairs beyond kMaxSendersPerStation, not learnt
};

class MavlinkRouter {
  public:
    /// Senders (system, component) learnt per station; a station that sends as more is not learnt further.
    static constexpr std::size_t kMaxSendersPerStation = 16;
    /// airsegd's own address with the autopilot (docs/ground-station.md): never a ground station's.
    static constexpr std::uint8_t kAirsegdSystem = 255;
    static constexpr std::uint8_t kAirsegdComponent = 191;

    /// A frame from `station` sent as (system, component).
    void heard(StationId station, std::uint8_t system, std::uint8_t component);
    /// The station is gone (a TCP client closed, a UDP peer timed out).
    void forget(StationId station);

    /// Of `stations`, those that get a frame with this addressee (nullopt: none, a broadcast); counted.
    std::vector<StationId> destinations(const std::optional<FrameTarget>& target,
                                        std::span<const StationId> stations);
    /// Whether one station gets it (not counted).
    [[nodiscard]] bool delivers(StationId station, const std::optional<FrameTarget>& target) const;

    [[nodiscard]] const MavlinkRouterStats& stats() const { return stats_; }
    [[nodiscard]] std::size_t stations() const { return senders_.size(); }

  private:
    static bool is_broadcast(const std::optional<FrameTarget>& target) {
        return !target || target->system == 0;
    }
    static bool to_airsegd(const std::optional<FrameTarget>& target) {
        return target && target->system == kAirsegdSystem && target->component == kAirsegdComponent;
    }

    std::map<StationId, std::set<std::pair<std::uint8_t, std::uint8_t>>> senders_;
    MavlinkRouterStats stats_;
};

}  // namespace airseg::ground
