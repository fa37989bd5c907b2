#pragma once
// What the simulated board sends: frames ready now, and replies held back by the "answer slowly" fault.
// Held-back frames are encoded when they are released, so sequence numbers stay in wire order.
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <utility>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::apmsim {

class Outbox {
  public:
    /// Frames waiting to be written are bounded: beyond this the oldest reply is dropped, as a full UART
    /// buffer on the board would drop it.
    static constexpr std::size_t kMaxHeld = 4096;

    explicit Outbox(mavlink::Version version) : encoder_(1, 1, version) {}

    /// Telemetry and spontaneous messages: ready at once.
    template <mavlink::Message M>
    void send(const M& m) {
        std::array<std::uint8_t, mavlink::kMaxFrameLength> frame{};
        const std::size_t n = encoder_.encode(m, frame);
        ready_.insert(ready_.end(), frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(n));
    }
    /// Answers to a request: delayed by the current reply delay (zero unless the board answers slowly).
    template <mavlink::Message M>
    void reply(const M& m) {
        if (reply_delay_ <= Duration::zero()) {
            send(m);
            return;
        }
        if (held_.size() >= kMaxHeld) {
            held_.erase(held_.begin());
        }
        held_.emplace(now_ + reply_delay_, [m](Outbox& self) { self.send(m); });
    }

    /// Sets the time and delay that reply() uses; call before handling each input.
    void set_reply_context(TimePoint now, Duration delay) {
        now_ = now;
        reply_delay_ = delay;
    }
    /// Encodes held replies whose time has come.
    void release(TimePoint now) {
        while (!held_.empty() && held_.begin()->first <= now) {
            auto encode = std::move(held_.begin()->second);
            held_.erase(held_.begin());
            encode(*this);
        }
    }
    TimePoint next_release() const { return held_.empty() ? kNever : held_.begin()->first; }
    /// Bytes ready to write; the outbox keeps nothing of them.
    std::vector<std::uint8_t> take() { return std::exchange(ready_, {}); }
    /// A reboot loses the answers still held back (bytes already taken or ready count as sent).
    void drop_held() { held_.clear(); }
    void set_version(mavlink::Version v) { encoder_.set_version(v); }

  private:
    mavlink::Encoder encoder_;
    std::vector<std::uint8_t> ready_;
    std::multimap<TimePoint, std::function<void(Outbox&)>> held_;
    TimePoint now_{};
    Duration reply_delay_{0};
};

}  // namespace airseg::apmsim
