#include "services/flightplan/reaction_monitor.hpp"

#include <cmath>
#include <sstream>

namespace airseg::flightplan {

ReactionSettings ReactionSettings::from_plan(const Plan& plan) {
    ReactionSettings s;
    s.link_loss = plan.reactions.link_loss;
    s.link_loss_after =
        std::chrono::duration_cast<Duration>(std::chrono::duration<double>(plan.reactions.link_loss_seconds));
    s.low_battery = plan.reactions.low_battery;
    s.low_battery_percent = plan.reactions.low_battery_percent;
    s.geofence = plan.reactions.geofence;
    s.frame = plan.frame;
    s.fence = plan.geofence_local;
    return s;
}

const char* to_string(ReactionTrigger::Cause cause) {
    switch (cause) {
        case ReactionTrigger::Cause::LinkLoss:
            return "link-loss";
        case ReactionTrigger::Cause::LinkRecovered:
            return "link-recovered";
        case ReactionTrigger::Cause::LowBattery:
            return "low-battery";
        case ReactionTrigger::Cause::Geofence:
            return "geofence";
    }
    return "?";
}

ReactionMonitor::ReactionMonitor(ReactionSettings settings) : s_(std::move(settings)) {}

void ReactionMonitor::fire(ReactionTrigger::Cause cause, const Reaction& reaction, TimePoint now,
                           std::string detail) {
    triggers_.push_back({cause, reaction, now, std::move(detail)});
}

void ReactionMonitor::on_link(bool up, TimePoint now) {
    if (up) {
        if (link_fired_ && s_.link_loss) {
            fire(ReactionTrigger::Cause::LinkRecovered, *s_.link_loss, now, {});
        }
        link_down_since_.reset();
        link_fired_ = false;
        return;
    }
    if (!link_down_since_) {
        link_down_since_ = now;
    }
    handle_timeout(now);
}

void ReactionMonitor::on_battery(double percent, TimePoint now) {
    if (!std::isfinite(percent) || percent < 0.0 || percent > 100.0) {
        ++rejected_samples_;
        return;
    }
    if (!s_.low_battery) {
        return;
    }
    if (!battery_fired_ && percent < s_.low_battery_percent) {
        battery_fired_ = true;
        std::ostringstream d;
        d << "battery " << percent << "% below " << s_.low_battery_percent << "%";
        fire(ReactionTrigger::Cause::LowBattery, *s_.low_battery, now, d.str());
    } else if (battery_fired_ && percent >= s_.low_battery_percent + s_.battery_hysteresis_percent) {
        battery_fired_ = false;
    }
}

void ReactionMonitor::on_position(LatLon position, TimePoint now) {
    if (!std::isfinite(position.lat) || !std::isfinite(position.lon) || std::abs(position.lat) > 90.0 ||
        std::abs(position.lon) > 180.0) {
        ++rejected_samples_;
        return;
    }
    if (!s_.geofence || s_.fence.size() < 3) {
        return;
    }
    const Enu p = s_.frame.to_local(position);
    const bool inside = point_in_polygon(p, s_.fence);
    if (!fence_fired_ && !inside) {
        fence_fired_ = true;
        std::ostringstream d;
        d << "position " << position.lat << ", " << position.lon << " outside the geofence";
        fire(ReactionTrigger::Cause::Geofence, *s_.geofence, now, d.str());
    } else if (fence_fired_ && inside && distance_to_boundary(p, s_.fence) >= s_.fence_hysteresis_m) {
        fence_fired_ = false;
    }
}

void ReactionMonitor::handle_timeout(TimePoint now) {
    if (link_down_since_ && !link_fired_ && s_.link_loss && now - *link_down_since_ >= s_.link_loss_after) {
        link_fired_ = true;
        std::ostringstream d;
        d << "ground link down for "
          << std::chrono::duration_cast<std::chrono::duration<double>>(now - *link_down_since_).count()
          << " s";
        fire(ReactionTrigger::Cause::LinkLoss, *s_.link_loss, now, d.str());
    }
}

TimePoint ReactionMonitor::poll_timeout() const {
    if (link_down_since_ && !link_fired_ && s_.link_loss) {
        return *link_down_since_ + s_.link_loss_after;
    }
    return kNever;
}

std::optional<ReactionTrigger> ReactionMonitor::poll_trigger() {
    if (triggers_.empty()) {
        return std::nullopt;
    }
    ReactionTrigger t = std::move(triggers_.front());
    triggers_.pop_front();
    return t;
}

}  // namespace airseg::flightplan
