#pragma once
// The ground link's state as a bus variable (Bus::publish_latest), published when it changes: what the flight
// plan's reactions and the status LED need, without reading the ground link's status section.

namespace airseg::groundlink {

struct LinkState {
    bool up = false;
};

}  // namespace airseg::groundlink
