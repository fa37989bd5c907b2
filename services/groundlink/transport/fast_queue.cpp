#include "services/groundlink/transport/fast_queue.hpp"

#include <algorithm>

namespace airseg::groundlink {

SendResult FastQueue::push(std::uint16_t topic, std::span<const std::uint8_t> msg) {
    for (auto& e : queue_) {
        if (e.topic == topic && !e.started) {
            e.bytes.assign(msg.begin(), msg.end());
            return SendResult::Replaced;
        }
    }
    SendResult result = SendResult::Accepted;
    if (queue_.size() >= cap_) {
        // The oldest message not being sent goes; a message half sent finishes so its fragments are not
        // wasted.
        auto victim = std::find_if(queue_.begin(), queue_.end(), [](const Entry& e) { return !e.started; });
        if (victim == queue_.end()) {
            victim = queue_.begin();
        }
        queue_.erase(victim);
        result = SendResult::DroppedOldest;
    }
    queue_.push_back(Entry{topic, std::vector<std::uint8_t>(msg.begin(), msg.end())});
    return result;
}

std::size_t FastQueue::next_min_data(std::size_t room) const {
    if (queue_.empty()) {
        return 0;
    }
    const Entry& e = queue_.front();
    if (e.started) {
        return std::min(e.fragment_size, e.bytes.size() - e.fragment_size * e.next_index);
    }
    if (e.bytes.size() + frame::fast_chunk_overhead(false) <= room) {
        return e.bytes.size();
    }
    return (e.bytes.size() + kMaxFragments - 1) / kMaxFragments;
}

std::optional<FastQueue::Piece> FastQueue::take(std::size_t room, bool force) {
    if (queue_.empty()) {
        return std::nullopt;
    }
    Entry& e = queue_.front();
    if (!e.started) {
        const bool fits_whole = e.bytes.size() + frame::fast_chunk_overhead(false) <= room;
        if (fits_whole || (e.bytes.empty() && force)) {
            Piece p{e.topic, false, 0, 0, 1, std::move(e.bytes), true};
            queue_.pop_front();
            return p;
        }
        const std::size_t fit =
            room > frame::fast_chunk_overhead(true) ? room - frame::fast_chunk_overhead(true) : 0;
        const std::size_t min_size = (e.bytes.size() + kMaxFragments - 1) / kMaxFragments;
        if (e.bytes.empty() || (fit < min_size && !force)) {
            return std::nullopt;
        }
        e.started = true;
        e.msg_id = next_msg_id_++;
        e.fragment_size = std::max<std::size_t>({fit, min_size, 1});
        e.count = static_cast<std::uint8_t>((e.bytes.size() + e.fragment_size - 1) / e.fragment_size);
        e.next_index = 0;
    } else if (std::min(e.fragment_size, e.bytes.size() - e.fragment_size * e.next_index) +
                       frame::fast_chunk_overhead(true) >
                   room &&
               !force) {
        return std::nullopt;
    }
    const std::size_t begin = e.fragment_size * e.next_index;
    const std::size_t end = std::min(e.bytes.size(), begin + e.fragment_size);
    Piece p{e.topic,
            true,
            e.msg_id,
            e.next_index,
            e.count,
            std::vector<std::uint8_t>(e.bytes.begin() + static_cast<std::ptrdiff_t>(begin),
                                      e.bytes.begin() + static_cast<std::ptrdiff_t>(end)),
            false};
    ++e.next_index;
    if (e.next_index == e.count) {
        p.message_done = true;
        queue_.pop_front();
    }
    return p;
}

}  // namespace airseg::groundlink
