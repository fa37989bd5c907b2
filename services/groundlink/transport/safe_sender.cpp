#include "services/groundlink/transport/safe_sender.hpp"

#include <algorithm>
#include <utility>

namespace airseg::groundlink {

SendResult SafeSender::enqueue(std::span<const std::uint8_t> msg) {
    if (msg.size() > max_message_) {
        return SendResult::TooLarge;
    }
    if (bytes_held_ + msg.size() > queue_bytes_) {
        return SendResult::QueueFull;
    }
    queue_.emplace_back(msg.begin(), msg.end());
    bytes_held_ += msg.size();
    return SendResult::Accepted;
}

std::size_t SafeSender::lost_size() const {
    for (const auto& s : inflight_) {
        if (s.lost) {
            return s.data.size();
        }
    }
    return 0;
}

SafeSender::Segment SafeSender::take_lost(TimePoint now, bool repeat_twice_lost) {
    for (std::size_t i = 0; i < inflight_.size(); ++i) {
        InFlight& s = inflight_[i];
        if (!s.lost) {
            continue;
        }
        ++s.transmissions;
        s.last_sent = now;
        s.lost = false;
        --lost_count_;
        const bool second_copy = std::exchange(s.second_copy, false);
        if (repeat_twice_lost && s.transmissions >= 3 && !second_copy) {
            // Lost twice already on a link losing many frames: it goes out again in the next frame
            // (frame_done()), which shortens the longest stalls at a small cost. Not in the same frame: both
            // copies would share its fate.
            s.repeat_due = true;
            repeats_due_ = true;
        }
        return Segment{static_cast<std::uint16_t>(una_ + i), s.end, s.data, true};
    }
    return Segment{};
}

std::optional<SafeSender::Segment> SafeSender::take_new(std::size_t max_data, bool force, TimePoint now) {
    if (!can_send_new()) {
        return std::nullopt;
    }
    const auto& msg = queue_.front();
    const std::size_t remaining = msg.size() - cut_offset_;
    const std::size_t fragments_left = kMaxFragments - cut_fragments_;
    const std::size_t min_size = (remaining + fragments_left - 1) / fragments_left;
    std::size_t size = std::min(remaining, max_data);
    if (size < min_size || (size == 0 && remaining > 0)) {
        if (!force) {
            return std::nullopt;
        }
        size = std::min(remaining, std::max<std::size_t>(min_size, 1));
    }
    InFlight s;
    s.data.assign(msg.begin() + static_cast<std::ptrdiff_t>(cut_offset_),
                  msg.begin() + static_cast<std::ptrdiff_t>(cut_offset_ + size));
    s.end = size == remaining;
    Segment out{static_cast<std::uint16_t>(next_), s.end, s.data, false};
    s.transmissions = 1;
    s.last_sent = now;
    cut_offset_ += size;
    ++cut_fragments_;
    if (s.end) {
        started_.push_back(std::move(queue_.front()));
        queue_.pop_front();
        cut_offset_ = 0;
        cut_fragments_ = 0;
    }
    inflight_.push_back(std::move(s));
    ++next_;
    return out;
}

void SafeSender::mark_acked(InFlight& s, AckResult& r, TimePoint now, TimePoint& newest_acked_send) {
    if (s.acked) {
        return;
    }
    s.acked = true;
    if (s.lost) {
        s.lost = false;
        --lost_count_;
    }
    ++r.newly_acked;
    r.newly_acked_bytes += s.data.size();
    if (s.last_sent > newest_acked_send) {
        newest_acked_send = s.last_sent;
        // Karn: only a segment sent once gives an unambiguous sample.
        r.rtt_sample = s.transmissions == 1 ? std::optional<Duration>(now - s.last_sent) : std::nullopt;
        r.rtt_sample_bytes = s.data.size();
    }
}

void SafeSender::pop_acked_front() {
    while (!inflight_.empty() && inflight_.front().acked) {
        bytes_held_ -= inflight_.front().data.size();
        if (inflight_.front().end) {
            started_.pop_front();
        }
        inflight_.pop_front();
        ++una_;
    }
}

SafeSender::AckResult SafeSender::on_ack(const frame::AckChunk& ack, TimePoint now, Duration reorder_slack) {
    AckResult r;
    const std::uint64_t span = next_ - una_;
    const auto delta = static_cast<std::uint16_t>(ack.next_expected - static_cast<std::uint16_t>(una_));
    if (delta > span) {
        return r;  // older than what is already acknowledged, or not ours
    }
    const std::uint64_t cum = una_ + delta;
    TimePoint newest{};
    for (std::uint64_t seq = una_; seq < cum; ++seq) {
        mark_acked(inflight_[static_cast<std::size_t>(seq - una_)], r, now, newest);
    }
    for (std::size_t bit = 0; bit < ack.bitmap.size() * 8; ++bit) {
        if (((ack.bitmap[bit / 8] >> (bit % 8)) & 1U) == 0) {
            continue;
        }
        const std::uint64_t seq = cum + 1 + bit;
        if (seq >= next_) {
            break;
        }
        mark_acked(inflight_[static_cast<std::size_t>(seq - una_)], r, now, newest);
    }
    if (r.newly_acked > 0) {
        probe_.reset();  // the peer hears again: acknowledgements judge the rest of the window
        for (auto& s : inflight_) {
            if (!s.acked && !s.lost && s.last_sent + reorder_slack < newest) {
                s.lost = true;
                ++lost_count_;
                ++r.newly_lost;
            }
        }
    }
    const std::uint64_t before = una_;
    pop_acked_front();
    r.progress = una_ != before;
    return r;
}

std::size_t SafeSender::on_timeout(TimePoint now, Duration rto) {
    if (probe_) {
        // Only the probe is timed until an acknowledgement arrives; it goes again, backed off, if it times
        // out.
        InFlight& p = inflight_[static_cast<std::size_t>(*probe_ - una_)];
        if (p.lost || p.last_sent + rto > now) {
            return 0;
        }
        p.lost = true;
        ++lost_count_;
        return 1;
    }
    std::optional<std::size_t> oldest;
    for (std::size_t i = 0; i < inflight_.size(); ++i) {
        const InFlight& s = inflight_[i];
        if (!s.acked && !s.lost && (!oldest || s.last_sent < inflight_[*oldest].last_sent)) {
            oldest = i;
        }
    }
    if (!oldest || inflight_[*oldest].last_sent + rto > now) {
        return 0;
    }
    inflight_[*oldest].lost = true;
    ++lost_count_;
    probe_ = una_ + *oldest;
    return 1;
}

void SafeSender::frame_done() {
    if (!std::exchange(repeats_due_, false)) {
        return;
    }
    for (auto& s : inflight_) {
        if (std::exchange(s.repeat_due, false) && !s.acked && !s.lost) {
            s.lost = true;
            s.second_copy = true;
            ++lost_count_;
        }
    }
}

TimePoint SafeSender::next_timeout(Duration rto) const {
    if (probe_) {
        const InFlight& p = inflight_[static_cast<std::size_t>(*probe_ - una_)];
        return p.lost ? kNever : p.last_sent + rto;
    }
    TimePoint t = kNever;
    for (const auto& s : inflight_) {
        if (!s.acked && !s.lost) {
            t = std::min(t, s.last_sent + rto);
        }
    }
    return t;
}

std::size_t SafeSender::reset() {
    const std::size_t started = started_.size() + (cut_fragments_ > 0 ? 1 : 0);
    for (auto it = started_.rbegin(); it != started_.rend(); ++it) {
        queue_.push_front(std::move(*it));
    }
    started_.clear();
    inflight_.clear();
    cut_offset_ = 0;
    cut_fragments_ = 0;
    una_ = next_ = 0;
    lost_count_ = 0;
    repeats_due_ = false;
    probe_.reset();
    bytes_held_ = 0;
    for (const auto& m : queue_) {
        bytes_held_ += m.size();
    }
    return started;
}

}  // namespace airseg::groundlink
