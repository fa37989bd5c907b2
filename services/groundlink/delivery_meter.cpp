#include "services/groundlink/delivery_meter.hpp"

#include <algorithm>

namespace airseg::groundlink {

void DeliveryMeter::on_pushed(TimePoint now) {
    ++pushed_;
    push_times_.push_back(now);
    while (push_times_.size() > 1 && now - push_times_.front() > 2 * kMaxSpan) {
        push_times_.pop_front();
    }
}

std::uint64_t DeliveryMeter::pushed_by(TimePoint t) const {
    // push_times_ holds the last pushes; those after t are not counted.
    const auto later = static_cast<std::uint64_t>(
        push_times_.end() - std::upper_bound(push_times_.begin(), push_times_.end(), t));
    return pushed_ - later;
}

void DeliveryMeter::on_report(std::uint32_t received, TimePoint now, Duration lag) {
    if (!reports_.empty() && received < reports_.back().received) {
        reset();  // the ground end restarted its count
    }
    const Report r{now, received, pushed_by(now - lag)};
    while (!reports_.empty() && now - reports_.front().at > kMaxSpan) {
        reports_.pop_front();
    }
    // The most recent earlier report that still spans enough pushed messages.
    for (auto it = reports_.rbegin(); it != reports_.rend(); ++it) {
        const auto pushed = r.pushed - std::min(r.pushed, it->pushed);
        if (pushed >= kMinMessages) {
            const auto got = r.received - std::min(r.received, it->received);
            loss_ = 1.0 - std::min(1.0, static_cast<double>(got) / static_cast<double>(pushed));
            break;
        }
    }
    reports_.push_back(r);
}

void DeliveryMeter::reset() {
    push_times_.clear();
    reports_.clear();
    pushed_ = 0;
    loss_.reset();
}

}  // namespace airseg::groundlink
