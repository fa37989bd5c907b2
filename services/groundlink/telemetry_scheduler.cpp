#include "services/groundlink/telemetry_scheduler.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace airseg::groundlink {

namespace {

Duration period_of(double hz) {
    return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(1.0 / hz));
}

}  // namespace

const char* to_string(TelemetryKind kind) {
    switch (kind) {
        case TelemetryKind::Vehicle:
            return "vehicle";
        case TelemetryKind::LinkStats:
            return "link_stats";
    }
    return "?";
}

std::optional<TelemetryKind> telemetry_kind_from_string(std::string_view name) {
    for (auto k : kAllTelemetryKinds) {
        if (name == to_string(k)) {
            return k;
        }
    }
    return std::nullopt;
}

std::vector<std::string> TelemetrySchedulerConfig::validate() const {
    std::vector<std::string> out;
    for (auto k : kAllTelemetryKinds) {
        const double hz = rate_hz[static_cast<std::size_t>(k)];
        if (!(hz >= 0 && hz <= kMaxHz)) {
            out.push_back(fmt::format("groundlink.telemetry.rates.{}: {} Hz is out of range 0..{}",
                                      to_string(k), hz, kMaxHz));
        }
    }
    if (!(budget_share > 0 && budget_share <= 1)) {
        out.push_back(
            fmt::format("groundlink.telemetry.budget_share: {} is out of range (0, 1]", budget_share));
    }
    if (!(min_hz > 0 && min_hz <= kMaxHz)) {
        out.push_back(fmt::format("groundlink.telemetry.min_hz: {} is out of range (0, {}]", min_hz, kMaxHz));
    }
    if (!(good_loss >= 0 && good_loss < weak_loss && weak_loss <= 1)) {
        out.push_back("groundlink.telemetry: need 0 <= good_loss < weak_loss <= 1");
    }
    return out;
}

TelemetryScheduler::TelemetryScheduler(TelemetrySchedulerConfig config, double link_rate_bytes_per_s,
                                       TimePoint now)
    : config_(std::move(config)), link_rate_(link_rate_bytes_per_s), last_change_(now) {
    requested_ = config_.rate_hz;
    next_due_.fill(now);
    recompute(now);
}

void TelemetryScheduler::set_config(const TelemetrySchedulerConfig& config, TimePoint now) {
    config_ = config;
    requested_ = config_.rate_hz;
    recompute(now);
}

std::optional<std::string> TelemetryScheduler::set_rate(TelemetryKind kind, double hz, TimePoint now) {
    if (!(hz >= 0 && hz <= TelemetrySchedulerConfig::kMaxHz)) {
        return fmt::format("{}: {} Hz is out of range 0..{}", to_string(kind), hz,
                           TelemetrySchedulerConfig::kMaxHz);
    }
    requested_[static_cast<std::size_t>(kind)] = hz;
    recompute(now);
    return std::nullopt;
}

void TelemetryScheduler::update_link(const LinkQuality& q, TimePoint now) {
    if (q.link_rate_bytes_per_s > 0) {
        link_rate_ = q.link_rate_bytes_per_s;
    }
    if (!q.up) {
        // Nothing is measured while the link is down: keep the factor, restart both observation periods.
        weak_since_ = good_since_ = kNever;
        recompute(now);
        return;
    }
    const double worst = std::max(q.loss, q.replaced_share);
    if (worst > config_.weak_loss) {
        good_since_ = kNever;
        if (weak_since_ == kNever) {
            weak_since_ = now;
        }
        weak_ = true;
        if (factor_ > config_.min_factor && now - weak_since_ >= config_.weak_after &&
            now - last_change_ >= config_.weak_after) {
            factor_ = std::max(config_.min_factor, factor_ / 2);
            last_change_ = now;
            ++lowerings_;
        }
    } else if (worst < config_.good_loss) {
        weak_since_ = kNever;
        weak_ = false;
        if (good_since_ == kNever) {
            good_since_ = now;
        }
        if (factor_ < 1.0 && now - good_since_ >= config_.recover_after &&
            now - last_change_ >= config_.recover_after) {
            factor_ = std::min(1.0, factor_ * 2);
            last_change_ = now;
            ++restorations_;
        }
    } else {
        // Between the thresholds: hold the factor and restart neither clock's count.
        weak_since_ = good_since_ = kNever;
    }
    recompute(now);
}

void TelemetryScheduler::recompute(TimePoint now) {
    budget_ = link_rate_ * config_.budget_share;
    double wanted = 0;
    for (auto k : kAllTelemetryKinds) {
        const auto i = static_cast<std::size_t>(k);
        wanted += requested_[i] * config_.wire_bytes[i];
    }
    const double scale = wanted > budget_ && wanted > 0 ? budget_ / wanted : 1.0;
    for (auto k : kAllTelemetryKinds) {
        const auto i = static_cast<std::size_t>(k);
        const double before = effective_[i];
        if (requested_[i] <= 0) {
            effective_[i] = 0;
            continue;
        }
        const double floor = std::min(requested_[i], config_.min_hz);
        effective_[i] = std::max(floor, requested_[i] * scale * factor_);
        if (effective_[i] != before) {
            // A faster rate takes effect at once; a slower one from the next message on.
            next_due_[i] = std::min(next_due_[i], next_on_grid(now, period_of(effective_[i])));
        }
    }
}

std::optional<TelemetryKind> TelemetryScheduler::poll_due(TimePoint now) {
    for (auto k : kAllTelemetryKinds) {
        const auto i = static_cast<std::size_t>(k);
        if (effective_[i] <= 0 || next_due_[i] > now) {
            continue;
        }
        // On the steady clock's grid of the period, as the daemon's other periodic work (time.hpp): kinds
        // whose periods divide a second come due together and with the whole-second ticks, one wake-up for
        // all. A late poll (a busy strand) skips to the next grid point: no burst to catch up.
        next_due_[i] = next_on_grid(now, period_of(effective_[i]));
        return k;
    }
    return std::nullopt;
}

TimePoint TelemetryScheduler::poll_timeout() const {
    TimePoint t = kNever;
    for (auto k : kAllTelemetryKinds) {
        const auto i = static_cast<std::size_t>(k);
        if (effective_[i] > 0) {
            t = std::min(t, next_due_[i]);
        }
    }
    return t;
}

Duration TelemetryScheduler::poll_slack() const {
    Duration slack = Duration::zero();
    for (auto k : kAllTelemetryKinds) {
        const auto i = static_cast<std::size_t>(k);
        if (effective_[i] > 0) {
            const Duration half = period_of(effective_[i]) / 2;
            slack = slack == Duration::zero() ? half : std::min(slack, half);
        }
    }
    return slack;
}

double TelemetryScheduler::requested_hz(TelemetryKind kind) const {
    return requested_[static_cast<std::size_t>(kind)];
}

double TelemetryScheduler::effective_hz(TelemetryKind kind) const {
    return effective_[static_cast<std::size_t>(kind)];
}

}  // namespace airseg::groundlink
