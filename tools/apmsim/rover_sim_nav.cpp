// RoverSim: modes, mission navigation and the vehicle's motion.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

namespace {

bool is_manual(RoverMode m) {
    return m == RoverMode::Manual || m == RoverMode::Learning || m == RoverMode::Steering ||
           m == RoverMode::Acro;
}

}  // namespace

DriveLimits RoverSim::limits() const {
    DriveLimits l;
    l.lateral_accel = std::max(0.1F, params_.get("TURN_MAX_G", 2)) * 9.80665;
    return l;
}

void RoverSim::freeze(bool on, TimePoint now) {
    // Motion up to `now` happens first; a frozen spell is then skipped, not caught up when released.
    advance(now);
    frozen_ = on;
    last_step_ = std::max(last_step_, now_);
}

bool RoverSim::physics_active() const {
    if (frozen_) {
        return false;
    }
    if (vehicle_.speed() != 0) {
        return true;
    }
    if (phase_ != BootPhase::Ready || !armed_) {
        return false;
    }
    if (is_navigating(mode_)) {
        return target_.has_value() && !loitering_;
    }
    return is_manual(mode_) &&
           std::any_of(rc_override_.begin(), rc_override_.end(), [](auto v) { return v != 0; });
}

bool RoverSim::set_mode(RoverMode mode, const std::string& cause, TimePoint now) {
    if (rover2_mission()) {
        return r2_set_mode(mode, cause, now);
    }
    if (mode == RoverMode::Auto && store_.count() <= 1) {
        text(mavlink::kSeverityInfo, "No Mission. Can't set AUTO.");
        return false;
    }
    const RoverMode from = mode_;
    if (from == RoverMode::Auto && mode != RoverMode::Auto) {
        mission_running_ = false;  // stopped; AUTO again resumes at the current item
    }
    mode_ = mode;
    target_.reset();
    leg_start_ = vehicle_.position();
    if (from != mode_) {
        mode_history_.push_back(ModeChange{now, from, mode_, cause, current_seq_, store_.count()});
    }
    // Entering AUTO may end the mission at once (nothing left to drive to), which switches to HOLD.
    switch (mode) {
        case RoverMode::Auto:
            if (from != RoverMode::Auto) {
                // ModeAuto::_enter() initialises the waypoint controller: a DO_CHANGE_SPEED of an earlier
                // run is forgotten and CRUISE_SPEED applies.
                speed_override_.reset();
                note_speed("mode", now);
            }
            if (mission_complete_ || current_seq_ == 0 || current_seq_ >= store_.count()) {
                current_seq_ = 1;  // start from the first item after home
            }
            mission_complete_ = false;
            mission_running_ = true;
            load_item(current_seq_, now);
            break;
        case RoverMode::Rtl:
        case RoverMode::SmartRtl:
            target_ = home_point();
            break;
        case RoverMode::Guided:
            target_ = guided_target_;
            break;
        default:
            break;
    }
    return true;
}

void RoverSim::load_item(std::uint16_t seq, TimePoint now) {
    // Commands that are not places (DO_ commands and the like) are passed over at once; DO_JUMP continues
    // at its target while it has repeats left (-1: forever). A mission of nothing but jumps ends.
    loitering_ = false;
    jumps_done_.resize(store_.count(), 0);
    for (std::size_t hops = 0; seq < store_.count() && seq > 0; ++hops) {
        const StoredItem& item = store_.at(seq);
        if (item.is_location() || item.command == kCmdNavReturnToLaunch || hops > store_.count()) {
            break;
        }
        if (item.command == kCmdDoChangeSpeed) {
            // Run while heading to the next place, as AP_Mission starts the do-commands after a nav command.
            // param2 is the speed (m/s); the speed type of param1 is not looked at (Rover's
            // do_change_speed()); zero or less leaves the speed.
            if (item.param2 > 0) {
                speed_override_ = item.param2;
                note_speed("mission", now, seq);
            }
        }
        if (item.command == kCmdDoJump) {
            const auto target = static_cast<long>(std::lround(item.param1));
            const auto repeats = static_cast<long>(std::lround(item.param2));
            if (target >= 1 && static_cast<std::size_t>(target) < store_.count() &&
                (repeats < 0 || jumps_done_[seq] < repeats)) {
                ++jumps_done_[seq];
                seq = static_cast<std::uint16_t>(target);
                continue;
            }
        }
        ++seq;
    }
    if (seq < store_.count() && seq > 0 && !store_.at(seq).is_location() &&
        store_.at(seq).command != kCmdNavReturnToLaunch) {
        seq = static_cast<std::uint16_t>(store_.count());  // only jumps: nothing to drive to
    }
    if (seq >= store_.count() || seq == 0) {
        mission_complete_ = true;
        mission_running_ = false;
        target_.reset();
        text(mavlink::kSeverityInfo, "Mission Complete");
        set_mode(RoverMode::Hold, "mission end", now);
        return;
    }
    const bool changed = current_seq_ != seq;
    current_seq_ = seq;
    const StoredItem& item = store_.at(seq);
    target_ = item.command == kCmdNavReturnToLaunch ? home_point() : point_of(item);
    leg_start_ = vehicle_.position();
    if (changed) {
        send_mission_current();
    }
}

void RoverSim::physics_step(TimePoint at) {
    const double dt = std::chrono::duration<double>(config_.physics_step).count();
    const DriveLimits lim = limits();
    // The motor's share of the battery (the electronics' share is counted in advance()).
    consumed_mah_ += 10.0 * std::abs(vehicle_.throttle()) * dt * 1000.0 / 3600.0;

    if (phase_ != BootPhase::Ready || !armed_) {
        vehicle_.stop(dt, lim);
        return;
    }
    if (is_manual(mode_)) {
        const auto stick = [&](int ch, std::uint16_t pwm) {
            const std::string p = "RC" + std::to_string(ch) + "_";
            const double trim = params_.get(p + "TRIM", 1500);
            const double span =
                pwm >= trim ? params_.get(p + "MAX", 1900) - trim : trim - params_.get(p + "MIN", 1100);
            return span > 0 ? std::clamp((pwm - trim) / span, -1.0, 1.0) : 0.0;
        };
        vehicle_.drive_manual(stick(1, rc_input(1, at)), stick(3, rc_input(3, at)), dt, lim);
        return;
    }
    if (!is_navigating(mode_) || !target_ || loitering_) {
        vehicle_.stop(dt, lim);
        return;
    }
    vehicle_.drive_to(*target_, cruise_speed(), dt, lim);
    if (rover2_mission()) {
        return;  // the 2.x navigate() task decides when a place is reached (r2_tick)
    }
    const double distance = distance_m(vehicle_.position(), *target_);
    const double radius = std::max(0.1F, params_.get("WP_RADIUS", 2));
    if (distance <= radius) {
        on_target_reached(distance, false, at);
        return;
    }
    // Past the item along the leg (the turn was too wide to get inside WP_RADIUS): it counts as passed.
    if (leg_start_ && distance_m(*leg_start_, *target_) > radius) {
        const double leg = bearing_rad(*leg_start_, *target_);
        const double to_vehicle = bearing_rad(*target_, vehicle_.position());
        if (std::cos(to_vehicle - leg) > 0 && distance < 4 * radius) {
            on_target_reached(distance, true, at);
        }
    }
}

void RoverSim::on_target_reached(double distance, bool passed, TimePoint now) {
    if (mode_ == RoverMode::Rtl || mode_ == RoverMode::SmartRtl) {
        text(mavlink::kSeverityInfo, "Reached Destination");
        set_mode(RoverMode::Hold, "rtl end", now);
        return;
    }
    if (mode_ == RoverMode::Guided) {
        text(mavlink::kSeverityInfo, "Reached Destination");
        guided_target_.reset();
        target_.reset();
        return;
    }
    const std::uint16_t seq = current_seq_;
    char line[50];
    std::snprintf(line, sizeof line, "%s waypoint #%u dist %um", passed ? "Passed" : "Reached",
                  static_cast<unsigned>(seq), static_cast<unsigned>(std::lround(distance)));
    text(mavlink::kSeverityInfo, line);
    if (config_.reached_style == ReachedStyle::MessageAndText) {
        mv::MissionItemReached r;
        r.seq = seq;
        out_.send(r);
    }
    if (reached_.size() >= kMaxReachedLog) {
        reached_.pop_front();
    }
    reached_.push_back(
        ReachedEvent{now, seq, distance, passed, target_.value_or(GeoPoint{}), store_.at(seq).command});
    ++reached_total_;
    if (store_.at(seq).command == kCmdNavLoiterUnlimited) {
        loitering_ = true;  // stays here; the mission does not advance past it
        return;
    }
    if (store_.at(seq).command == kCmdNavReturnToLaunch) {
        load_item(static_cast<std::uint16_t>(store_.count()), now);  // RTL ends the mission
        return;
    }
    const GeoPoint here = target_.value_or(GeoPoint{});
    load_item(static_cast<std::uint16_t>(seq + 1), now);
    // The next item at the very point just reached is a leg of no length: ArduPilot takes it as passed at
    // once (Location::line_path_proportion() gives the end of the line for two points closer than a
    // millimetre), it does not turn round to drive back into WP_RADIUS.
    if (target_ && mode_ == RoverMode::Auto && !loitering_ && distance_m(here, *target_) < 0.001 &&
        current_seq_ != seq) {
        on_target_reached(distance, true, now);
    }
}

bool RoverSim::set_current(std::uint16_t seq, TimePoint now) {
    if (seq == 0) {
        seq = 1;  // home is never a target
    }
    if (seq >= store_.count()) {
        return false;
    }
    current_seq_ = seq;
    mission_complete_ = false;
    if (mode_ == RoverMode::Auto) {
        mission_running_ = true;
        load_item(seq, now);  // retarget at once
    }
    return true;
}

bool RoverSim::guided_goto(const StoredItem& item) {
    if (mode_ != RoverMode::Guided) {
        return false;
    }
    guided_target_ = point_of(item);
    target_ = guided_target_;
    leg_start_ = vehicle_.position();
    return true;
}

void RoverSim::mission_changed() {
    jumps_done_.assign(store_.count(), 0);
    params_.set("MIS_TOTAL", static_cast<float>(store_.count()));
}

bool RoverSim::rc_pilot(RoverMode mode, TimePoint now) {
    advance(now);
    if (phase_ != BootPhase::Ready || mode == RoverMode::Initialising) {
        return false;
    }
    return set_mode(mode, "rc pilot", now);
}

bool RoverSim::force_mode(RoverMode mode, TimePoint now) {
    handle_timeout(now);
    if (phase_ != BootPhase::Ready || mode == RoverMode::Initialising) {
        return false;
    }
    const bool ok = set_mode(mode, "board", now);
    out_.release(now);
    return ok;
}

}  // namespace airseg::apmsim
