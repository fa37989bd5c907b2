#include "services/groundlink/transport/fast_reassembly.hpp"

#include <algorithm>

namespace airseg::groundlink {

std::optional<std::vector<std::uint8_t>> FastReassembly::add(const frame::FastChunk& c, TimePoint now) {
    auto it = std::find_if(partial_.begin(), partial_.end(), [&](const Partial& p) {
        return p.priority == c.priority && p.topic == c.topic && p.msg_id == c.msg_id && p.count == c.count;
    });
    if (it == partial_.end()) {
        if (partial_.size() >= kMaxPartial) {
            auto oldest =
                std::min_element(partial_.begin(), partial_.end(),
                                 [](const Partial& a, const Partial& b) { return a.started < b.started; });
            dropped_ += oldest->discarding ? 0 : 1;
            partial_.erase(oldest);
        }
        Partial p;
        p.priority = c.priority;
        p.topic = c.topic;
        p.msg_id = c.msg_id;
        p.count = c.count;
        p.pieces.resize(c.count);
        p.have.resize(c.count, false);
        p.started = now;
        partial_.push_back(std::move(p));
        it = std::prev(partial_.end());
    }
    Partial& p = *it;
    if (p.discarding || p.have[c.index]) {
        return std::nullopt;
    }
    if (p.bytes + c.data.size() > max_message_) {
        // Kept, empty, until it expires: the message's remaining fragments are ignored, not started afresh.
        p.discarding = true;
        p.pieces = {};
        ++dropped_;
        ++oversized_;
        return std::nullopt;
    }
    p.have[c.index] = true;
    p.pieces[c.index].assign(c.data.begin(), c.data.end());
    p.bytes += c.data.size();
    if (++p.received < p.count) {
        return std::nullopt;
    }
    std::vector<std::uint8_t> out;
    out.reserve(p.bytes);
    for (const auto& piece : p.pieces) {
        out.insert(out.end(), piece.begin(), piece.end());
    }
    partial_.erase(it);
    return out;
}

std::size_t FastReassembly::expire(TimePoint now) {
    std::size_t n = 0;
    std::erase_if(partial_, [&](const Partial& p) {
        const bool expired = p.started + timeout_ <= now;
        n += expired && !p.discarding ? 1 : 0;  // an oversized one was counted when it was dropped
        return expired;
    });
    dropped_ += n;
    return n;
}

TimePoint FastReassembly::next_deadline() const {
    TimePoint t = kNever;
    for (const auto& p : partial_) {
        t = std::min(t, p.started + timeout_);
    }
    return t;
}

}  // namespace airseg::groundlink
