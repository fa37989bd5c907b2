#pragma once
// Which pre-shared key the ground end uses, and so which role it has.
//
// The transport authenticates frames with one key. With a monitor key configured besides the control key,
// the service runs the transport on one of them; when the link is not up and frames keep failing their MAC
// check while none passes, the peer uses the other key, and the service rebuilds the transport with it. A
// frame's MAC can only be made with the key itself, so the role follows from the key the link works with.
// Two ticks in a row of failures only are needed: a ground end still sending frames of a session the vehicle
// has just restarted also fails the check for a moment, with the right key.
// Sans-IO: counters in, a decision out.
#include <cstdint>

#include "services/common/command_dispatcher.hpp"

namespace airseg::groundlink {

class KeySelector {
  public:
    explicit KeySelector(bool has_monitor_key) : has_monitor_(has_monitor_key) {}

    /// The role of the key in use.
    [[nodiscard]] Role role() const { return monitor_ ? Role::Monitor : Role::Control; }
    [[nodiscard]] std::uint64_t switches() const { return switches_; }

    /// Once per statistics tick, with the transport's counters since the previous tick (of the transport in
    /// use). Returns true when the transport must be rebuilt with the other key (role() already says which).
    bool update(bool link_up, std::uint64_t new_mac_failures, std::uint64_t new_valid_frames) {
        if (!has_monitor_ || link_up || new_valid_frames > 0 || new_mac_failures == 0) {
            suspect_ticks_ = 0;
            return false;
        }
        if (++suspect_ticks_ < kTicksBeforeSwitch) {
            return false;
        }
        suspect_ticks_ = 0;
        monitor_ = !monitor_;
        ++switches_;
        return true;
    }

  private:
    static constexpr int kTicksBeforeSwitch = 2;
    bool has_monitor_;
    int suspect_ticks_ = 0;
    bool monitor_ = false;
    std::uint64_t switches_ = 0;
};

}  // namespace airseg::groundlink
