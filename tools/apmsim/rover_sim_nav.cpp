// RoverSim: modes, mission navigation and the vehicle's motion.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "tools/apmsim/corner_speed.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

namespace {

constexpr double kGravity = 9.80665;
constexpr double kStopped = 0.1;            // m/s: a car going slower than this has stopped at its waypoint
constexpr double kSamePoint = 0.01;         // m: a leg shorter than this has no length
constexpr float kMinWaypointSpeed = 0.05F;  // AR_WPNAV_SPEED_MIN

bool is_manual(RoverMode m) {
    return m == RoverMode::Manual || m == RoverMode::Learning || m == RoverMode::Steering ||
           m == RoverMode::Acro;
}

/// Seconds a navigation item holds the car where it is reached (ModeAuto::do_nav_wp(): p1 of a waypoint, a
/// negative one counting 0; LOITER_TIME's time).
double hold_seconds(const StoredItem& item) {
    if (item.command == kCmdNavWaypoint || item.command == kCmdNavLoiterTime) {
        return std::max(0.0, std::floor(static_cast<double>(item.param1)));
    }
    return 0.0;
}

/// A navigation command the car always stops at (loiters, a held waypoint).
bool stops_at(const StoredItem& item) {
    return item.command == kCmdNavLoiterUnlimited || item.command == kCmdNavLoiterTurns ||
           item.command == kCmdNavLoiterTime || hold_seconds(item) > 0;
}

double wrap_pi(double a) {
    return std::remainder(a, 2 * std::numbers::pi);
}

}  // namespace

DriveLimits RoverSim::limits() const {
    DriveLimits l;
    const float g =
        config_.firmware.cornering ? params_.get("ATC_TURN_MAX_G", 0.6F) : params_.get("TURN_MAX_G", 2);
    l.lateral_accel = std::max(0.1F, g) * kGravity;
    return l;
}

void RoverSim::freeze(bool on, TimePoint now) {
    // Motion up to `now` happens first; a frozen spell is then skipped, not caught up when released.
    advance(now);
    frozen_ = on;
    last_step_ = std::max(last_step_, now_);
}

void RoverSim::swap_battery(TimePoint now) {
    advance(now);  // what was drawn up to now came from the old battery
    consumed_mah_ = 0;
}

bool RoverSim::physics_active() const {
    if (frozen_) {
        return false;
    }
    if (vehicle_.speed() != 0) {
        return true;
    }
    if (phase_ != BootPhase::Ready || !is_armed()) {
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
    wait_until_.reset();
    if (from != mode_) {
        mode_history_.push_back(ModeChange{now, from, mode_, cause, current_seq_, store_.count()});
        if (is_navigating(mode_)) {
            // AR_WPNav::init(): the speed is WP_SPEED again and the S-curve starts from rest (modern).
            planned_speed_ = 0;
            if (config_.firmware.auto_speed == FirmwareProfile::AutoSpeed::WpSpeed) {
                speed_override_ = std::max(kMinWaypointSpeed, params_.get("WP_SPEED", 2));
                note_speed("mode", now);
            }
        }
    }
    // Entering AUTO may end the mission at once (nothing left to drive to), which switches to HOLD.
    switch (mode) {
        case RoverMode::Auto:
            if (from != RoverMode::Auto &&
                config_.firmware.auto_speed == FirmwareProfile::AutoSpeed::CruiseSpeed) {
                // ModeAuto::_enter() initialises the waypoint controller: a DO_CHANGE_SPEED of an earlier
                // run is forgotten and CRUISE_SPEED applies.
                speed_override_.reset();
                note_speed("mode", now);
            }
            if (mission_complete_ || current_seq_ == 0 || current_seq_ >= store_.count()) {
                current_seq_ = 1;  // start from the first item after home
                leg_speeds_.clear();
            }
            mission_complete_ = false;
            mission_running_ = true;
            load_item(current_seq_, now);
            // ModeAuto primes its change detector right after mission.start_or_resume().
            change_detector_.reset();
            check_mission_change(now);
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
            // do_change_speed()); below AR_WPNav's 0.05 m/s (-1: no change) it leaves the speed.
            const float least =
                config_.firmware.auto_speed == FirmwareProfile::AutoSpeed::WpSpeed ? kMinWaypointSpeed : 0.0F;
            if (item.param2 > least) {
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

    if (phase_ != BootPhase::Ready || !is_armed()) {
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
    if (config_.firmware.cornering && !rover2_mission()) {
        nav_modern_step(dt, lim, at);
        return;
    }
    vehicle_.drive_to(*target_, cruise_speed(), dt, lim);
    if (mode_ == RoverMode::Auto) {
        note_leg_speed(vehicle_.speed());
    }
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
    ReachedEvent event{now, seq, distance, passed, target_.value_or(GeoPoint{})};
    event.command = store_.at(seq).command;
    take_leg_stats(event);
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
    reached_.push_back(event);
    ++reached_total_;
    if (store_.at(seq).command == kCmdNavLoiterUnlimited) {
        loitering_ = true;  // stays here; the mission does not advance past it
        return;
    }
    if (store_.at(seq).command == kCmdNavReturnToLaunch) {
        load_item(static_cast<std::uint16_t>(store_.count()), now);  // RTL ends the mission
        return;
    }
    if (config_.firmware.cornering && hold_seconds(store_.at(seq)) > 0) {
        // ModeAuto::verify_nav_wp(): held there for the item's seconds, then on (nav_modern_step()).
        wait_until_ = now + std::chrono::duration_cast<Duration>(
                                std::chrono::duration<double>(hold_seconds(store_.at(seq))));
        return;
    }
    continue_after(seq, now);
}

void RoverSim::continue_after(std::uint16_t seq, TimePoint now) {
    const GeoPoint here = target_.value_or(GeoPoint{});
    load_item(static_cast<std::uint16_t>(seq + 1), now);
    if (config_.firmware.cornering && target_ && mode_ == RoverMode::Auto) {
        leg_start_ = here;  // the S-curve's next leg starts at the destination just reached
    }
    // The next item at the very point just reached is a leg of no length: ArduPilot takes it as passed at
    // once (Location::line_path_proportion() gives the end of the line for two points closer than a
    // millimetre), it does not turn round to drive back into WP_RADIUS.
    if (target_ && mode_ == RoverMode::Auto && !loitering_ && distance_m(here, *target_) < 0.001 &&
        current_seq_ != seq) {
        on_target_reached(distance_m(vehicle_.position(), *target_), true, now);
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
        wait_until_.reset();
        leg_speeds_.clear();
        planned_speed_ = 0;   // the new leg is planned from where the car is, from rest (AR_WPNav)
        load_item(seq, now);  // retarget at once
    }
    return true;
}

// The modern waypoint controller (AR_WPNav, ModeAuto), one physics step: the change detector, a timed
// waypoint's wait, the S-curve's planned speed (corner_speed.hpp) and when a waypoint counts as reached.
void RoverSim::nav_modern_step(double dt, const DriveLimits& lim, TimePoint at) {
    check_mission_change(at);
    if (!target_ || loitering_) {
        vehicle_.stop(dt, lim);
        return;
    }
    if (wait_until_) {
        vehicle_.stop(dt, lim);
        if (at >= *wait_until_) {
            wait_until_.reset();
            continue_after(current_seq_, at);
        }
        return;
    }
    const double cruise = cruise_speed();
    bool stop = false;
    const double corner = corner_speed_here(cruise, lim, stop);
    const double radius = std::max(0.1F, params_.get("WP_RADIUS", 2));
    const double accel = std::max(0.1F, params_.get("ATC_ACCEL_MAX", 1));
    const double limit =
        approach_speed_limit(corner, distance_m(vehicle_.position(), *target_), stop ? 0.0 : radius, accel);
    planned_speed_ = std::min({planned_speed_ + accel * dt, cruise, limit});
    vehicle_.drive_to(*target_, planned_speed_, dt, lim);
    if (mode_ == RoverMode::Auto) {
        note_leg_speed(vehicle_.speed());
    }
    const double distance = distance_m(vehicle_.position(), *target_);
    // A waypoint the car stops at counts once it has stopped there (the S-curve ends at rest on it).
    const bool must_stop = stop && mode_ == RoverMode::Auto;
    if (distance <= radius && (!must_stop || vehicle_.speed() <= kStopped)) {
        on_target_reached(distance, false, at);
        return;
    }
    if (leg_start_ && distance_m(*leg_start_, *target_) > radius) {
        const double leg = bearing_rad(*leg_start_, *target_);
        const double to_vehicle = bearing_rad(*target_, vehicle_.position());
        if (std::cos(to_vehicle - leg) > 0 && distance < 4 * radius) {
            on_target_reached(distance, true, at);
        }
    }
}

// The speed the car leaves its target at (ModeAuto::do_nav_wp() and AR_WPNav::set_desired_location()): a
// stop (`stop` set, 0) at a loiter or a held waypoint, with no next navigation command (DO_JUMP followed),
// before a next leg of no length (a next command without a place counts as one: Location::sanitize()) and
// in the modes that drive to one point; otherwise the corner's speed.
double RoverSim::corner_speed_here(double cruise, const DriveLimits& lim, bool& stop) const {
    stop = true;
    if (mode_ != RoverMode::Auto || current_seq_ == 0 || current_seq_ >= store_.count()) {
        return 0.0;
    }
    const StoredItem& item = store_.at(current_seq_);
    if (stops_at(item) || item.command == kCmdNavReturnToLaunch) {
        return 0.0;
    }
    const auto next = next_nav_cmd(store_, static_cast<std::uint16_t>(current_seq_ + 1), jumps_done_);
    if (!next) {
        return 0.0;
    }
    const StoredItem& after = store_.at(*next);
    if (after.lat_e7 == 0 && after.lon_e7 == 0) {
        return 0.0;
    }
    const GeoPoint next_point = point_of(after);
    if (distance_m(*target_, next_point) < kSamePoint) {
        return 0.0;
    }
    double turn = 0.0;
    if (leg_start_ && distance_m(*leg_start_, *target_) >= kSamePoint) {
        turn = wrap_pi(bearing_rad(*target_, next_point) - bearing_rad(*leg_start_, *target_));
    }
    const double radius = std::max(0.1F, params_.get("WP_RADIUS", 2));
    const double v = corner_speed(turn, cruise, lim.lateral_accel, radius);
    stop = v <= 0.0;
    return v;
}

// ModeAuto::update(): a change of the current navigation command or of the next two restarts the current
// one in the WP submode (driving to a place; not while holding at a waypoint, loitering or returning home):
// it is read again and re-planned from where the car is, from rest.
void RoverSim::check_mission_change(TimePoint now) {
    if (!config_.firmware.mission_change_restart || mode_ != RoverMode::Auto || !mission_running_) {
        return;
    }
    jumps_done_.resize(store_.count(), 0);
    if (!change_detector_.check(store_, current_seq_, jumps_done_)) {
        return;
    }
    if (!target_ || loitering_ || wait_until_ || current_seq_ >= store_.count() ||
        store_.at(current_seq_).command == kCmdNavReturnToLaunch) {
        return;
    }
    ++counters_.auto_restarts;
    text(mavlink::kSeverityCritical, "Auto mission changed, restarted command");
    planned_speed_ = 0;
    load_item(current_seq_, now);
}

void RoverSim::take_leg_stats(ReachedEvent& event) {
    if (leg_speeds_.empty()) {
        return;
    }
    event.leg_s =
        static_cast<double>(leg_speeds_.size()) * std::chrono::duration<double>(config_.physics_step).count();
    const auto middle = leg_speeds_.begin() + static_cast<std::ptrdiff_t>(leg_speeds_.size() / 2);
    std::nth_element(leg_speeds_.begin(), middle, leg_speeds_.end());
    event.median_speed = *middle;
    leg_speeds_.clear();
}

void RoverSim::note_leg_speed(double speed) {
    if (leg_speeds_.size() < kMaxLegSamples) {  // about 5.8 hours of one leg: the median of those
        leg_speeds_.push_back(static_cast<float>(speed));
    }
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
