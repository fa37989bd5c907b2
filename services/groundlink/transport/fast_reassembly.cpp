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
            partial_.erase(oldest);
            ++dropped_;
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
    if (p.have[c.index]) {
        return std::nullopt;
    }
    if (p.bytes + c.data.size() > max_message_) {
        partial_.erase(it);
        ++dropped_;
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
    const auto before = partial_.size();
    std::erase_if(partial_, [&](const Partial& p) { return p.started + timeout_ <= now; });
    const std::size_t n = before - partial_.size();
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
