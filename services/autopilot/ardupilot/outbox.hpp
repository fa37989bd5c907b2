#pragma once
// The frames the driver cores want sent to the autopilot, in order. One encoder (one sequence counter) for
// every core on the link, so the autopilot sees one consistent sender. Bounded: when the port cannot keep up
// the oldest frames are dropped and counted; every protocol above has its own retries.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"

namespace airseg::autopilot::ardupilot {

class Outbox {
  public:
    static constexpr std::size_t kMaxFrames = 256;

    Outbox(std::uint8_t sysid, std::uint8_t compid, mavlink::Version version)
        : encoder_(sysid, compid, version) {}

    template <mavlink::Message M>
    void send(const M& message) {
        if (frames_.size() >= kMaxFrames) {
            frames_.pop_front();
            ++dropped_;
        }
        frames_.push_back(encoder_.encode(message));
    }

    /// The next frame to write, oldest first.
    std::optional<std::vector<std::uint8_t>> poll_transmit() {
        if (frames_.empty()) {
            return std::nullopt;
        }
        auto f = std::move(frames_.front());
        frames_.pop_front();
        return f;
    }

    bool empty() const { return frames_.empty(); }
    std::size_t size() const { return frames_.size(); }
    std::uint64_t dropped() const { return dropped_; }
    std::uint8_t sysid() const { return encoder_.sysid(); }
    std::uint8_t compid() const { return encoder_.compid(); }
    /// Whether an answer is meant for this sender. Zero means anyone (old boards, broadcast). The component
    /// counts too: a ground station on the same system id (QGroundControl's default 255) sends the same
    /// requests, and the autopilot answers each requester's system and component.
    bool addressed_to_us(std::uint8_t target_system, std::uint8_t target_component) const {
        return (target_system == 0 || target_system == sysid()) &&
               (target_component == 0 || target_component == compid());
    }
    void set_version(mavlink::Version v) { encoder_.set_version(v); }

  private:
    mavlink::Encoder encoder_;
    std::deque<std::vector<std::uint8_t>> frames_;
    std::uint64_t dropped_ = 0;
};

}  // namespace airseg::autopilot::ardupilot
