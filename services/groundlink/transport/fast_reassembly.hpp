#pragma once
// Reassembles fragmented Fast messages. Fragments may be lost, so an incomplete message is dropped after
// fast_reassembly_timeout; at most kMaxPartial messages are in progress (the oldest is dropped for a new
// one).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "base/time.hpp"
#include "services/groundlink/transport/frame.hpp"

namespace airseg::groundlink {

class FastReassembly {
  public:
    static constexpr std::size_t kMaxPartial = 8;

    FastReassembly(Duration timeout, std::size_t max_message)
        : timeout_(timeout), max_message_(max_message) {}

    /// Returns the whole message once its last missing fragment arrives.
    std::optional<std::vector<std::uint8_t>> add(const frame::FastChunk& c, TimePoint now);
    /// Drops messages older than the timeout; returns how many.
    std::size_t expire(TimePoint now);
    [[nodiscard]] TimePoint next_deadline() const;
    [[nodiscard]] std::uint64_t dropped() const { return dropped_; }
    /// Of those, messages that grew beyond max_message_size (only a misbehaving peer sends those).
    [[nodiscard]] std::uint64_t oversized() const { return oversized_; }
    void reset() { partial_.clear(); }

  private:
    struct Partial {
        std::uint8_t priority = 0;
        std::uint16_t topic = 0;
        std::uint8_t msg_id = 0;
        std::uint8_t count = 0;
        std::size_t received = 0;
        std::size_t bytes = 0;
        std::vector<std::vector<std::uint8_t>> pieces;
        std::vector<bool> have;
        TimePoint started{};
        bool discarding = false;  // grew beyond max_message_size: its remaining fragments are ignored
    };
    Duration timeout_;
    std::size_t max_message_;
    std::vector<Partial> partial_;
    std::uint64_t dropped_ = 0;
    std::uint64_t oversized_ = 0;
};

}  // namespace airseg::groundlink
