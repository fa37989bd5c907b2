#pragma once
// Receiving half of one Safe channel: holds out-of-order segments within the window, reassembles messages in
// sequence order and says what to acknowledge (cumulative point plus a bitmap of segments held beyond it).
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include "base/time.hpp"
#include "services/groundlink/transport/frame.hpp"

namespace airseg::groundlink {

class SafeReceiver {
  public:
    SafeReceiver(std::size_t window, std::size_t max_message) : window_(window), max_message_(max_message) {}

    enum class Accept : std::uint8_t {
        Fresh,        ///< new segment stored or delivered
        Duplicate,    ///< seen before (its acknowledgement was probably lost)
        OutOfWindow,  ///< beyond the window: dropped, will be resent
    };
    Accept on_segment(const frame::SafeChunk& seg);

    /// Completed messages, in order.
    std::optional<std::vector<std::uint8_t>> pop_message();
    [[nodiscard]] frame::AckChunk make_ack(std::uint8_t channel) const;
    /// Segments held beyond a gap: the sender should hear about the gap at once.
    [[nodiscard]] bool has_gap() const { return !held_.empty(); }
    void reset();
    /// Messages dropped because they grew beyond max_message_size (only a misbehaving peer sends those).
    [[nodiscard]] std::uint64_t oversize_dropped() const { return oversize_dropped_; }

  private:
    void consume(std::vector<std::uint8_t>&& data, bool end);

    std::size_t window_, max_message_;
    std::uint64_t next_ = 0;
    std::map<std::uint64_t, std::pair<std::vector<std::uint8_t>, bool>> held_;
    std::vector<std::uint8_t> partial_;
    bool discarding_ = false;  // rest of an oversize message
    std::deque<std::vector<std::uint8_t>> complete_;
    std::uint64_t oversize_dropped_ = 0;
};

}  // namespace airseg::groundlink
