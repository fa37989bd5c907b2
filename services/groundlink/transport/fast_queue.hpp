#pragma once
// Fast messages of one priority waiting to be sent: the freshest value of a topic replaces an unsent one (in
// place, so a busy topic does not lose its turn), the queue holds at most `cap` messages and drops the
// oldest, and a message larger than a frame goes out as up to 255 fragments.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "services/groundlink/transport/frame.hpp"
#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundlink {

class FastQueue {
  public:
    explicit FastQueue(std::size_t cap) : cap_(cap) {}

    SendResult push(std::uint16_t topic, std::span<const std::uint8_t> msg);
    [[nodiscard]] bool empty() const { return queue_.empty(); }
    [[nodiscard]] std::size_t size() const { return queue_.size(); }

    struct Piece {
        std::uint16_t topic = 0;
        bool fragmented = false;
        std::uint8_t msg_id = 0;
        std::uint8_t index = 0;
        std::uint8_t count = 1;
        std::vector<std::uint8_t> data;
        bool message_done = false;  ///< this piece completes the message
    };
    /// Data bytes the next piece needs at least (its whole size when it goes unfragmented).
    [[nodiscard]] std::size_t next_min_data(std::size_t room) const;
    /// Takes the next piece fitting in `room` chunk bytes; `force` allows one larger than room when a message
    /// cannot otherwise stay within 255 fragments.
    std::optional<Piece> take(std::size_t room, bool force);

  private:
    struct Entry {
        std::uint16_t topic = 0;
        std::vector<std::uint8_t> bytes;
        bool started = false;
        std::uint8_t msg_id = 0;
        std::size_t fragment_size = 0;
        std::uint8_t count = 1;
        std::uint8_t next_index = 0;
    };
    std::size_t cap_;
    std::deque<Entry> queue_;
    std::uint8_t next_msg_id_ = 0;
};

}  // namespace airseg::groundlink
