// Driver: the speed of the leg being driven. A plan's cruise and per-leg speeds travel as the speed of each
// mission item (MissionItem::speed, the leg to that item). When the board heads for an item in AUTO whose
// speed differs from the last one it confirmed, the driver sets it: MAV_CMD_DO_CHANGE_SPEED (COMMAND_LONG,
// confirmed by COMMAND_ACK ACCEPTED) on boards that have the command, or the parameter the board drives AUTO
// at (speed_param(): WP_SPEED on current Rover, CRUISE_SPEED on ArduRover 2.x; PARAM_SET, confirmed by the
// PARAM_VALUE read back) on those that do not (2.x; also any board that answers the command UNSUPPORTED or
// DENIED, or never answers it). A board with WP_SPEED gets the command even when configured as apm2: it
// reads WP_SPEED only on entering AUTO.
//  - Every entry into AUTO brings the board's own speed back (current Rover: ModeAuto::_enter() initialises
//    AR_WPNav at WP_SPEED), and so does a reboot: the speed confirmed is then the board's own, and the plan's
//    is sent again. A parameter, kept in the board's EEPROM, survives both and is sent only when it changes.
//  - A command the board answers FAILED or TEMPORARILY_REJECTED (current Rover outside AUTO, or below its
//    0.05 m/s) is asked again at the next entry into AUTO or for another speed.
//  - A leg without a speed goes at the board's own speed, the parameter as it was before the first change
//    (kept for the driver's lifetime). On a board set by parameter that value is written back when the plan
//    ends (the board heads for its final Stop) or the mission is cleared.
#include <cmath>

#include "services/autopilot/ardupilot/driver.hpp"

#include "services/autopilot/mavlink/enums.hpp"

namespace airseg::autopilot::ardupilot {

namespace mav = airseg::mavlink;

namespace {
constexpr float kSpeedTypeGround = 1.0F;
constexpr float kThrottleUnchanged = -1.0F;
constexpr double kSameSpeed = 0.005;  // m/s: below this two speeds are the same
constexpr const char* kCruiseSpeed = "CRUISE_SPEED";
constexpr const char* kWpSpeed = "WP_SPEED";

bool same(double a, double b) {
    return std::fabs(a - b) < kSameSpeed;
}
}  // namespace

const char* Driver::speed_param() const {
    return params_.cached(kWpSpeed) ? kWpSpeed : kCruiseSpeed;
}

void Driver::forget_speed() {
    speed_set_.reset();
    speed_request_.reset();
    speed_refused_.reset();
}

// A board with WP_SPEED runs AR_WPNav (Rover 3.x and later), which has MAV_CMD_DO_CHANGE_SPEED, whatever
// autopilot.board says: its WP_SPEED is read only when AUTO is entered, so the command is the way to set a
// leg's speed while it drives.
void Driver::on_params_known() {
    if (params_.cached(kWpSpeed)) {
        speed_by_param_ = false;
    }
}

void Driver::on_auto_entered() {
    speed_refused_.reset();
    if (speed_by_param_) {
        return;  // the parameter holds
    }
    // The command's speed is gone: what the board confirms now is its own AUTO speed.
    if (const auto own = params_.cached(speed_param())) {
        speed_set_ = *own;
    } else {
        speed_set_.reset();
    }
}

void Driver::restore_board_speed(TimePoint now) {
    if (!speed_by_param_ || !board_speed_ || !speed_set_ || same(*speed_set_, *board_speed_) ||
        (speed_request_ && same(speed_request_->value, *board_speed_))) {
        return;
    }
    send_speed(*board_speed_, 0, now);
}

void Driver::update_speed(TimePoint now) {
    if (!ready() || state_ != VehicleState::WaypointNavigation || auto_check_.active()) {
        return;  // a restarted mission is set back first: its slot is not the leg being driven
    }
    const std::uint16_t slot = reported_current_;
    if (slot < 1 || static_cast<std::size_t>(slot) > mission_.size()) {
        return;
    }
    const MissionItem& item = mission_[slot - 1];
    if (item.kind == MissionItem::Kind::Stop) {
        restore_board_speed(now);  // the plan has ended here
        return;
    }
    if (item.kind != MissionItem::Kind::Waypoint) {
        return;
    }
    double v = 0.0;
    if (item.speed && *item.speed > 0.0) {
        v = *item.speed;
        if (!board_speed_) {
            // What the board drives at by itself, before the first change: legs without a speed go back to
            // it.
            if (const auto own = params_.cached(speed_param())) {
                board_speed_ = *own;
            }
        }
    } else if (board_speed_ && (speed_set_ || speed_request_)) {
        v = *board_speed_;  // a leg without a speed of its own after legs with one
    } else {
        return;
    }
    if (speed_request_ ? same(speed_request_->value, v) : (speed_set_ && same(*speed_set_, v))) {
        return;
    }
    if (!speed_request_ && speed_refused_ && same(*speed_refused_, v)) {
        return;
    }
    send_speed(v, 0, now);
}

void Driver::send_speed(double value, unsigned attempt, TimePoint now) {
    if (speed_by_param_) {
        speed_request_ =
            SpeedRequest{value, attempt, kNever, params_.set(speed_param(), static_cast<float>(value), now)};
        drain_clients(now);
        return;
    }
    mav::CommandLong m;
    m.target_system = config_.target_sysid;
    m.target_component = config_.target_compid;
    m.command = mavlink::kCmdDoChangeSpeed;
    m.confirmation = static_cast<std::uint8_t>(std::min(attempt, 255u));
    m.param1 = kSpeedTypeGround;
    m.param2 = static_cast<float>(value);
    m.param3 = kThrottleUnchanged;
    out_.send(m);
    speed_request_ = SpeedRequest{value, attempt, now + config_.mode_timeout, 0};
}

void Driver::on_speed_ack(std::uint8_t result, TimePoint now) {
    if (!speed_request_ || speed_request_->param_op != 0) {
        return;
    }
    if (result == mavlink::kResultInProgress) {
        return;
    }
    const double v = speed_request_->value;
    if (result == mavlink::kResultAccepted) {
        speed_request_.reset();
        speed_set_ = v;
        speed_refused_.reset();
        ++speed_changes_;
        return;
    }
    if (result == mavlink::kResultFailed || result == mavlink::kResultTemporarilyRejected) {
        // The board has the command but not now (current Rover outside AUTO): the next entry into AUTO asks
        // again.
        speed_request_.reset();
        speed_refused_ = v;
        return;
    }
    // UNSUPPORTED, DENIED...: this board takes its speed from a parameter.
    speed_by_param_ = true;
    send_speed(v, 0, now);
}

void Driver::speed_timeout(TimePoint now) {
    if (!speed_request_ || now < speed_request_->deadline) {
        return;
    }
    const SpeedRequest r = *speed_request_;
    if (r.attempt < config_.mode_retries) {
        send_speed(r.value, r.attempt + 1, now);
        return;
    }
    speed_by_param_ = true;  // never answered: a board without the command
    send_speed(r.value, 0, now);
}

bool Driver::on_speed_param_done(const ParamCompletion& c, TimePoint now) {
    if (!speed_request_ || speed_request_->param_op == 0 || c.id != speed_request_->param_op) {
        return false;
    }
    const double v = speed_request_->value;
    speed_request_.reset();
    if (c.result == RequestResult::Ok) {
        speed_set_ = v;
        speed_refused_.reset();
        ++speed_changes_;
    } else if (c.result != RequestResult::Cancelled) {
        // Not asked again for the same speed (a board without the parameter would be asked forever): the
        // next different speed tries again. The confirmed speed stays what it was.
        speed_refused_ = v;
    }
    update_speed(now);
    return true;
}

}  // namespace airseg::autopilot::ardupilot
