#pragma once
// When the ground sends its reception report (how many pushed messages it received, for the vehicle's
// DeliveryMeter). It is due once a second, and doubles as the uplink's keepalive: while the ground has
// nothing else to say, it goes in place of the transport's empty probe, whenever a path owes one
// (Transport::probe_owed: the next transmit poll, such as the one after the vehicle's telemetry arrives,
// would send it) and just before a probe's own timer (Transport::probe_deadline). The idle uplink then
// carries the probes alone, instead of the probes and, once a second, a report; each frame the vehicle hears
// is a wake-up of its daemon. Sans-IO: the caller asks at its timer and before handing the transport input.
#include "base/time.hpp"
#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundside {

class ReportTiming {
  public:
    static constexpr Duration kPeriod = std::chrono::seconds(1);
    /// Ahead of the probe's own timer by more than timers drift apart.
    static constexpr Duration kAheadOfProbe = std::chrono::milliseconds(20);
    /// Reports at least this far apart, should a report's frame be held back (the air gate) and the
    /// probe's deadline therefore not move.
    static constexpr Duration kMinGap = std::chrono::milliseconds(250);

    /// Whether the report goes now (then send it and call sent()): at the timer, and before each input.
    [[nodiscard]] bool due(TimePoint now, const groundlink::Transport& transport) const;
    void sent(TimePoint now) { last_ = now; }
    /// When to call due() again.
    [[nodiscard]] TimePoint next_check(TimePoint now, const groundlink::Transport& transport) const;

  private:
    TimePoint last_{};
};

/// The earliest probe deadline over the transport's paths (kNever when none is probed).
TimePoint earliest_probe(const groundlink::Transport& transport);

}  // namespace airseg::groundside
