#include "services/groundlink/transport/air_estimate.hpp"

#include <algorithm>

namespace airseg::groundlink {

void AirEstimate::WindowedMin::add(Duration v, TimePoint now) {
    if (mins[0] == kUnset && mins[1] == kUnset && mins[2] == kUnset) {
        bucket_start = now;
    }
    if (now - bucket_start >= 3 * kBucket) {
        mins = {kUnset, kUnset, kUnset};  // a long quiet: start afresh rather than step through it
        bucket_start = now;
    }
    while (now - bucket_start >= kBucket) {
        mins[2] = mins[1];
        mins[1] = mins[0];
        mins[0] = kUnset;
        bucket_start += kBucket;
    }
    mins[0] = std::min(mins[0], v);
}

Duration AirEstimate::WindowedMin::value() const {
    const Duration m = *std::min_element(mins.begin(), mins.end());
    return m == kUnset ? Duration::zero() : m;
}

AirEstimate::AirEstimate(double configured, TimePoint now)
    : configured_(configured), carried_(configured), period_start_(now) {}

void AirEstimate::on_round_trip(Duration rtt, std::optional<Duration> exchange, TimePoint now) {
    if (rtt <= Duration::zero()) {
        return;
    }
    base_.add(rtt, now);
    if (exchange) {
        ++round_trips_;
        fixed_.add(std::max(Duration::zero(), rtt - *exchange), now);
    }
}

void AirEstimate::on_sent(std::size_t bytes, bool held) {
    ++period_sent_;
    period_sent_bytes_ += bytes;
    if (held) {
        ++period_held_;
    }
}

double AirEstimate::delivered() const {
    static_assert(kSamples == 3, "the median below is of three");
    const double a = samples_[0];
    const double b = samples_[1];
    switch (sample_count_) {
        case 0:
            return 0.0;
        case 1:
            return a;
        case 2:
            return std::max(a, b);  // the upper of two: a bunch of acknowledgements late is the likelier
        default:
            return std::max(std::min(a, b), std::min(std::max(a, b), samples_[2]));
    }
}

bool AirEstimate::update(TimePoint now) {
    const Duration elapsed = now - period_start_;
    if (elapsed < kPeriod) {
        return false;
    }
    const double before = carried_;
    // Saturated: nearly every frame of the period left more waiting for the pacing. Only then does what
    // was acknowledged say what the air carries rather than what the application offered.
    // And it wrote at least half its pace: a trickle of small frames with a retransmission waiting is
    // not a full link.
    const double seconds = std::chrono::duration<double>(elapsed).count();
    const bool saturated = period_sent_ >= 3 && period_held_ * 10 >= period_sent_ * 8 &&
                           static_cast<double>(period_sent_bytes_) >= 0.5 * carried_ * seconds;
    if (saturated) {
        judge(seconds);
    }
    noise_ *= kNoiseMemory;
    period_start_ = now;
    period_acked_ = 0;
    period_acked_segments_ = 0;
    period_heard_ = 0;
    period_lost_ = 0;
    period_sent_ = 0;
    period_sent_bytes_ = 0;
    period_held_ = 0;
    return carried_ != before;
}

void AirEstimate::judge(double seconds) {
    samples_[next_sample_] = static_cast<double>(period_acked_ + period_heard_) / seconds;
    next_sample_ = (next_sample_ + 1) % kSamples;
    sample_count_ = std::min(sample_count_ + 1, kSamples);
    const std::size_t judged = period_acked_segments_ + period_lost_;
    if (trial_) {
        judge_trial(judged, seconds);
        return;
    }
    if (judged < kJudgedSegments) {
        return;
    }
    const double loss = static_cast<double>(period_lost_) / static_cast<double>(judged);
    // Losses beyond the air's known noise while it delivers well under the pace: perhaps the radio's
    // buffer overflowing (a byte dropped there takes its whole frame), which a slower pace cures. Judged
    // on the recent average, not one second's count: a trial started on a chance peak would find the
    // losses "cured" by mere return to their mean.
    recent_loss_ = loss_seen_ ? kLossAverage * loss + (1 - kLossAverage) * recent_loss_ : loss;
    loss_seen_ = true;
    const bool suspect = period_lost_ > 0 && recent_loss_ > 2 * noise_ + kNoiseSlack && sample_count_ >= 2 &&
                         delivered() < kKeepingUp * carried_;
    if (quiet_periods_ > 0) {
        --quiet_periods_;
    }
    if (suspect && quiet_periods_ == 0 && carried_ > configured_ / 4) {
        trial_ = Trial{carried_, recent_loss_, delivered(), kTrialPeriods};
        trial_->step_from = carried_;
        carried_ = std::max(configured_ / 4, carried_ * kBackOff);
    } else if (loss <= 2 * noise_) {
        // Quickly back towards the pace of the last overflow, slowly past it.
        const bool near = overflowed_at_ > 0.0 && carried_ > kNear * overflowed_at_;
        carried_ = std::min(configured_, carried_ + (near ? kProbeStep / 4 : kProbeStep) * configured_);
    }
}

void AirEstimate::judge_trial(std::size_t judged, double seconds) {
    // A slower pace on trial. On an air that cannot carry the old pace, what arrives does not fall with
    // the pace (the air, not the pace, set it) and the losses of the overflowing buffer fall; noise on
    // the air would take the same share of less. So: losses cured, done; what arrives held up but losses
    // remain, still too fast, a step further down; what arrives fell, noise, and the pace goes back to
    // where the trial started.
    if (trial_->periods_left < kTrialPeriods) {  // the first second drains the queue
        trial_->lost += period_lost_;
        trial_->judged += judged;
        trial_->bytes += static_cast<double>(period_acked_ + period_heard_);
        trial_->seconds += seconds;
    }
    if (--trial_->periods_left > 0) {
        return;
    }
    const Trial t = *trial_;
    trial_.reset();
    if (t.judged < kJudgedSegments) {
        carried_ = t.pace_before;  // too little went through to tell: as it was
        quiet_periods_ = kAfterTrial;
        return;
    }
    const double during = static_cast<double>(t.lost) / static_cast<double>(t.judged);
    const bool held_up = t.bytes / t.seconds >= kHeldUp * t.delivered_before;
    recent_loss_ = during;
    if (during < kCured * t.loss_before) {
        overflowed_at_ = t.step_from;
        ++overflows_;
    } else if ((held_up || during > std::max(kWorse * t.loss_before, t.loss_before + kWorseBy)) &&
               carried_ > configured_ / 4) {
        // Losses growing even at the slower pace: a buffer still filling, not steady noise.
        trial_ = Trial{t.pace_before, t.loss_before, t.delivered_before, kTrialPeriods};
        trial_->step_from = carried_;
        carried_ = std::max(configured_ / 4, carried_ * kBackOff);
    } else {
        carried_ = t.pace_before;
        noise_ = std::max(noise_, during);
        quiet_periods_ = kAfterTrial;
    }
}

Duration AirEstimate::turnaround() const {
    return fixed_.value() / 2;
}

}  // namespace airseg::groundlink
