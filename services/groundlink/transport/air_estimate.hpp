#pragma once
// What the air of a radio pair really carries, measured from the link's own traffic (docs/ground-link.md,
// "Measured air"). Two figures:
//   carried     payload bytes/s to pace for. Judged once a second while this end sends as fast as its
//               pacing allows. Segments lost in such a second while the air delivers well under the pace
//               may be the radio's buffer overflowing (the air took less than the pacing gave it): the pace
//               steps down for a few seconds' trial, and stays down only if the losses fell with it;
//               losses it did not cure are noise on the air, remembered as such. A clean second lets the
//               pace creep up again. Never past the configured rate nor below a quarter of it.
//   delivered   payload bytes/s the peer acknowledged in such seconds, with what this end heard from the
//               peer meanwhile (the air both share; the median of the last few seconds, since
//               acknowledgements come in bunches): what the air was seen to carry.
//   turnaround  what the quickest recent round trip of small frames took beyond its two frames' own serial
//               and air time, halved (a round trip changes the sender twice); radio latency and the peer's
//               reaction are in it too. Shown, not paced by: the carried rate already pays for it.
// Sans-IO like the transport: time is passed in.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "base/time.hpp"

namespace airseg::groundlink {

class AirEstimate {
  public:
    static constexpr Duration kPeriod = std::chrono::seconds(1);
    static constexpr std::size_t kSamples = 3;
    /// Delivering at least this share of the pace, the air keeps up with it.
    static constexpr double kKeepingUp = 0.8;
    /// A second with losses that may be an overflow steps the pace down by this factor for a trial of
    /// kTrialPeriods; the losses must fall under kCured of what they were for the step to stay ...
    static constexpr double kBackOff = 0.85;
    static constexpr std::size_t kTrialPeriods = 3;  // the first drains the queue and is not counted
    static constexpr double kCured = 0.5;
    /// Delivering at least this share of what arrived before the trial, the air held up: it, not the pace,
    /// sets what arrives.
    static constexpr double kHeldUp = 0.95;
    /// Losses past this multiple of what they were, and by kWorseBy at least (noise wanders): a buffer
    /// still filling; a further step down too.
    static constexpr double kWorse = 2.0;
    static constexpr double kWorseBy = 0.15;
    static constexpr double kLossAverage = 0.3;  // weight of the latest second in the recent loss
    /// Fewer segments than this in a second say nothing of its losses.
    static constexpr std::size_t kJudgedSegments = 8;
    /// Saturated seconds after a trial that found noise (or could not tell) before the next trial.
    static constexpr std::size_t kAfterTrial = 10;
    /// Losses a trial found the slower pace did not cure are noise: only more than twice that (plus
    /// kNoiseSlack) is suspect again. The memory fades by kNoiseMemory a second.
    static constexpr double kNoiseSlack = 0.01;
    static constexpr double kNoiseMemory = 0.98;
    /// ... and each clean, saturated second raises it by this share of the configured rate (a quarter of
    /// it within kNear of the pace that last overflowed).
    static constexpr double kProbeStep = 0.02;
    static constexpr double kNear = 0.95;

    /// `configured`: payload bytes/s the configuration says the link carries (the upper bound).
    AirEstimate(double configured, TimePoint now);

    /// A segment sent once and acknowledged after `rtt`; `exchange` is the time its frame and the
    /// acknowledgement's take on the serial ports and the air as configured, without turnaround, when the
    /// frames are small enough for it to be known.
    void on_round_trip(Duration rtt, std::optional<Duration> exchange, TimePoint now);
    void on_acked(std::size_t payload_bytes, std::size_t segments) {
        period_acked_ += payload_bytes;
        period_acked_segments_ += segments;
    }
    void on_lost(std::size_t segments) { period_lost_ += segments; }
    /// Payload heard from the peer: on a shared (half-duplex) air it is carried too.
    void on_heard(std::size_t payload_bytes) { period_heard_ += payload_bytes; }
    /// A frame of `bytes` went out; `held`: more data waited for the pacing (the air, not the application,
    /// set the pace).
    void on_sent(std::size_t bytes, bool held);
    /// Closes the period once it has lasted kPeriod; true when carried() changed.
    bool update(TimePoint now);

    /// Payload bytes/s to pace for.
    [[nodiscard]] double carried() const { return carried_; }
    /// Payload bytes/s the link was seen to deliver while saturated (0 before it was).
    [[nodiscard]] double delivered() const;
    [[nodiscard]] double configured() const { return configured_; }
    /// Turnaround as measured (zero before any round trip).
    [[nodiscard]] Duration turnaround() const;
    /// Least round trip of recent ones (zero before the first).
    [[nodiscard]] Duration base_rtt() const { return base_.value(); }
    [[nodiscard]] std::uint64_t overflows() const { return overflows_; }
    /// Round trips the turnaround was measured on.
    [[nodiscard]] std::uint64_t round_trips() const { return round_trips_; }

  private:
    // A windowed minimum: the least of the current bucket and the two before (20-30 s in all).
    struct WindowedMin {
        static constexpr Duration kUnset = Duration::max();
        static constexpr Duration kBucket = std::chrono::seconds(10);
        std::array<Duration, 3> mins{kUnset, kUnset, kUnset};
        TimePoint bucket_start{};
        void add(Duration v, TimePoint now);
        [[nodiscard]] Duration value() const;
    };

    double configured_;
    double carried_;
    std::array<double, kSamples> samples_{};
    std::size_t sample_count_ = 0;
    std::size_t next_sample_ = 0;
    WindowedMin base_;
    WindowedMin fixed_;  // round trip less its frames' own time
    TimePoint period_start_;
    struct Trial {
        double pace_before = 0.0;
        double loss_before = 0.0;
        double delivered_before = 0.0;
        std::size_t periods_left = 0;
        std::size_t lost = 0;
        std::size_t judged = 0;
        double step_from = 0.0;  // the pace this step of the trial came down from
        double bytes = 0.0;      // payload that arrived (both ways) in the seconds counted
        double seconds = 0.0;
    };
    void judge(double seconds);
    void judge_trial(std::size_t judged, double seconds);

    std::optional<Trial> trial_;
    double noise_ = 0.0;  // share of segments lost to noise, as trials found it
    std::size_t quiet_periods_ = 0;
    double recent_loss_ = 0.0;  // share of segments lost, averaged over saturated seconds
    bool loss_seen_ = false;
    std::size_t period_acked_ = 0;
    std::size_t period_acked_segments_ = 0;
    std::size_t period_heard_ = 0;
    std::size_t period_lost_ = 0;
    std::size_t period_sent_ = 0;
    std::size_t period_sent_bytes_ = 0;
    std::size_t period_held_ = 0;
    double overflowed_at_ = 0.0;
    std::uint64_t overflows_ = 0;
    std::uint64_t round_trips_ = 0;
};

}  // namespace airseg::groundlink
