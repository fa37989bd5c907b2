#include "services/groundlink/transport/safe_receiver.hpp"

#include <algorithm>

namespace airseg::groundlink {

SafeReceiver::Accept SafeReceiver::on_segment(const frame::SafeChunk& seg) {
    const auto ahead = static_cast<std::uint16_t>(seg.seq - static_cast<std::uint16_t>(next_));
    if (ahead >= 0x8000U) {
        return Accept::Duplicate;  // behind next_: already delivered
    }
    if (ahead >= window_) {
        return Accept::OutOfWindow;
    }
    const std::uint64_t seq = next_ + ahead;
    if (seq != next_) {
        if (held_.contains(seq)) {
            return Accept::Duplicate;
        }
        held_.emplace(seq,
                      std::make_pair(std::vector<std::uint8_t>(seg.data.begin(), seg.data.end()), seg.end));
        return Accept::Fresh;
    }
    consume(std::vector<std::uint8_t>(seg.data.begin(), seg.data.end()), seg.end);
    ++next_;
    while (!held_.empty() && held_.begin()->first == next_) {
        auto node = held_.extract(held_.begin());
        consume(std::move(node.mapped().first), node.mapped().second);
        ++next_;
    }
    return Accept::Fresh;
}

void SafeReceiver::consume(std::vector<std::uint8_t>&& data, bool end) {
    if (!discarding_) {
        if (partial_.size() + data.size() > max_message_) {
            partial_.clear();
            discarding_ = true;
            ++oversize_dropped_;
        } else {
            partial_.insert(partial_.end(), data.begin(), data.end());
        }
    }
    if (end) {
        if (!discarding_) {
            complete_.push_back(std::move(partial_));
        }
        partial_.clear();
        discarding_ = false;
    }
}

std::optional<std::vector<std::uint8_t>> SafeReceiver::pop_message() {
    if (complete_.empty()) {
        return std::nullopt;
    }
    auto m = std::move(complete_.front());
    complete_.pop_front();
    return m;
}

frame::AckChunk SafeReceiver::make_ack(std::uint8_t channel) const {
    frame::AckChunk a;
    a.channel = channel;
    a.next_expected = static_cast<std::uint16_t>(next_);
    for (const auto& [seq, seg] : held_) {
        const std::uint64_t bit = seq - next_ - 1;
        if (bit >= frame::kMaxBitmapBytes * 8) {
            break;
        }
        const auto byte = static_cast<std::size_t>(bit / 8);
        if (a.bitmap.size() <= byte) {
            a.bitmap.resize(byte + 1, 0);
        }
        a.bitmap[byte] = static_cast<std::uint8_t>(a.bitmap[byte] | (1U << (bit % 8)));
    }
    return a;
}

void SafeReceiver::reset() {
    next_ = 0;
    held_.clear();
    partial_.clear();
    discarding_ = false;
    complete_.clear();
}

}  // namespace airseg::groundlink
