#include "services/groundlink/frame_forwarder.hpp"

#include <algorithm>
#include <cmath>

namespace airseg::groundlink {

using Delivery = autopilot::ForwardedFrame::Delivery;

std::vector<std::string> FrameForwarderConfig::validate() const {
    std::vector<std::string> problems;
    if (!(budget_bytes_per_s >= 0) || !std::isfinite(budget_bytes_per_s)) {
        problems.emplace_back("groundlink.mavlink_forward.budget_bytes_per_s must be 0 (default) or more");
    }
    for (const auto& [id, hz] : rate_hz) {
        if (!(hz >= 0 && hz <= 50)) {
            problems.push_back("groundlink.mavlink_forward.rates: message " + std::to_string(id) +
                               " must be 0 .. 50 Hz");
        }
    }
    if (!(default_hz >= 0 && default_hz <= 50)) {
        problems.emplace_back("groundlink.mavlink_forward default rate must be 0 .. 50 Hz");
    }
    return problems;
}

FrameForwarder::FrameForwarder(FrameForwarderConfig config, double link_rate_bytes_per_s, TimePoint now)
    : config_(std::move(config)),
      budget_(config_.budget_bytes_per_s > 0
                  ? config_.budget_bytes_per_s
                  : FrameForwarderConfig::kDefaultBudgetShare * link_rate_bytes_per_s),
      tokens_(budget_ * config_.burst_s),
      refilled_at_(now) {}

double FrameForwarder::rate_of(std::uint32_t id) const {
    const auto it = config_.rate_hz.find(id);
    return it != config_.rate_hz.end() ? it->second : config_.default_hz;
}

void FrameForwarder::offer(const autopilot::ForwardedFrame& frame, [[maybe_unused]] TimePoint now) {
    ++stats_.offered;
    if (frame.delivery == Delivery::Reliable) {
        if (reliable_bytes_ + frame.bytes.size() > config_.reliable_queue_bytes) {
            ++stats_.dropped;
            return;
        }
        reliable_bytes_ += frame.bytes.size();
        reliable_.push_back(Out{frame.delivery, frame.id, frame.bytes});
        return;
    }
    const double hz = rate_of(frame.id);
    if (hz <= 0) {
        ++stats_.filtered;
        return;
    }
    Slot& slot = slots_[frame.id];
    ++slot.stats.offered;
    if (slot.pending) {
        ++stats_.replaced;
        ++slot.stats.replaced;
    }
    slot.bytes = frame.bytes;
    slot.pending = true;
    slot.interval = std::chrono::duration_cast<Duration>(std::chrono::duration<double>(1.0 / hz));
}

void FrameForwarder::link_down() {
    for (auto& [id, slot] : slots_) {
        if (slot.pending) {
            ++stats_.stale;
            ++slot.stats.stale;
            slot.pending = false;
            slot.bytes.clear();
        }
    }
}

void FrameForwarder::put_back(Out out) {
    if (out.delivery != Delivery::Reliable) {
        return;
    }
    --stats_.forwarded;
    stats_.forwarded_bytes -= out.bytes.size();
    tokens_ += static_cast<double>(out.bytes.size()) + config_.overhead_bytes;
    reliable_bytes_ += out.bytes.size();
    reliable_.push_front(std::move(out));
}

FrameForwarderStats FrameForwarder::stats() const {
    FrameForwarderStats s = stats_;
    s.reliable_queued = reliable_.size();
    s.reliable_queued_bytes = reliable_bytes_;
    for (const auto& [id, slot] : slots_) {
        s.freshest_by_id.emplace(id, slot.stats);
    }
    return s;
}

void FrameForwarder::clear() {
    stats_.dropped += reliable_.size();
    reliable_.clear();
    reliable_bytes_ = 0;
    for (auto& [id, slot] : slots_) {
        if (slot.pending) {
            ++stats_.dropped;
            slot.pending = false;
        }
    }
}

void FrameForwarder::refill(TimePoint now) {
    if (now > refilled_at_) {
        const double dt = std::chrono::duration<double>(now - refilled_at_).count();
        tokens_ = std::min(budget_ * config_.burst_s, tokens_ + budget_ * dt);
        refilled_at_ = now;
    }
}

std::map<std::uint32_t, FrameForwarder::Slot>::iterator FrameForwarder::due_slot(TimePoint now) {
    auto best = slots_.end();
    for (auto it = slots_.begin(); it != slots_.end(); ++it) {
        if (it->second.pending && it->second.next_allowed <= now &&
            (best == slots_.end() || it->second.next_allowed < best->second.next_allowed)) {
            best = it;
        }
    }
    return best;
}

FrameForwarder::Out FrameForwarder::take(Out out) {
    tokens_ -= static_cast<double>(out.bytes.size()) + config_.overhead_bytes;
    ++stats_.forwarded;
    stats_.forwarded_bytes += out.bytes.size();
    return out;
}

std::optional<FrameForwarder::Out> FrameForwarder::poll(TimePoint now) {
    refill(now);
    if (tokens_ < 0) {
        return std::nullopt;
    }
    const auto slot = due_slot(now);
    const bool reliable_waits = !reliable_.empty();
    if (slot == slots_.end() && !reliable_waits) {
        return std::nullopt;
    }
    const bool reliable = reliable_waits && (slot == slots_.end() || reliable_turn_);
    reliable_turn_ = !reliable;
    if (reliable) {
        Out out = std::move(reliable_.front());
        reliable_.pop_front();
        reliable_bytes_ -= out.bytes.size();
        return take(std::move(out));
    }
    Slot& s = slot->second;
    s.pending = false;
    // On schedule, the id keeps its grid (a frame arriving a little late does not slow the id down); after
    // a pause or a wait for the budget it starts afresh from now, so it earns no burst.
    s.next_allowed = now - s.next_allowed < s.interval ? s.next_allowed + s.interval : now + s.interval;
    ++s.stats.forwarded;
    if (s.last_forwarded != TimePoint{}) {
        s.stats.longest_gap = std::max(s.stats.longest_gap, now - s.last_forwarded);
    }
    s.last_forwarded = now;
    return take(Out{Delivery::Freshest, slot->first, std::move(s.bytes)});
}

TimePoint FrameForwarder::poll_timeout() const {
    TimePoint due = kNever;
    if (!reliable_.empty()) {
        due = refilled_at_;
    }
    for (const auto& [id, slot] : slots_) {
        if (slot.pending) {
            due = std::min(due, slot.next_allowed);
        }
    }
    if (due == kNever || tokens_ >= 0 || budget_ <= 0) {
        return due;
    }
    const auto refill_wait =
        std::chrono::duration_cast<Duration>(std::chrono::duration<double>(-tokens_ / budget_));
    return std::max(due, refilled_at_ + refill_wait + Duration{1});
}

}  // namespace airseg::groundlink
