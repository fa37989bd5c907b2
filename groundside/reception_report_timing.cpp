#include "groundside/reception_report_timing.hpp"

#include <algorithm>

namespace airseg::groundside {

TimePoint earliest_probe(const groundlink::Transport& transport) {
    TimePoint t = kNever;
    for (std::size_t i = 0; i < transport.config().paths; ++i) {
        t = std::min(t, transport.probe_deadline(i));
    }
    return t;
}

bool ReportTiming::due(TimePoint now, const groundlink::Transport& transport) const {
    if (!transport.link_up() || now < last_ + kMinGap) {
        return false;
    }
    if (now >= last_ + kPeriod) {
        return true;
    }
    const TimePoint probe = earliest_probe(transport);
    if (probe != kNever && now + kAheadOfProbe >= probe) {
        return true;
    }
    for (std::size_t i = 0; i < transport.config().paths; ++i) {
        if (transport.probe_owed(i, now)) {
            return true;
        }
    }
    return false;
}

TimePoint ReportTiming::next_check(TimePoint now, const groundlink::Transport& transport) const {
    if (!transport.link_up()) {
        return now + kPeriod;
    }
    const TimePoint probe = earliest_probe(transport);
    const TimePoint before_probe = probe == kNever ? kNever : probe - kAheadOfProbe;
    return std::max({std::min(last_ + kPeriod, before_probe), last_ + kMinGap, now});
}

}  // namespace airseg::groundside
