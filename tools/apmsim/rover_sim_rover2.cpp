// RoverSim as APMrover2 2.4x (the rover2 firmware profile): the command processor of commands_process.pde,
// commands_logic.pde and commands.pde, the modes of system.pde, the navigation tasks of APMrover2.pde and
// the command handlers of GCS_Mavlink.pde, all of ArduRover v2.43 (before Rover moved to AP_Mission in 2.46).
// The variables keep the firmware's names and types (uint8_t indices wrap as they do there); each function
// says which firmware function it stands for.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

namespace {

constexpr std::uint8_t kNoCommand = 0;
// WAIT_COMMAND of defines.h, not seen in the source read; 255 is what ArduPlane of the same years uses.
constexpr std::uint8_t kWaitCommand = 255;
// gcs_severity (GCS_MAVLink.h): the 2.x firmware sends these numbers as the STATUSTEXT severity.
constexpr std::uint8_t kLow = 1;
constexpr std::uint8_t kHigh = 3;
// The scheduler runs navigate() and update_commands() every 5 ticks of the 50 Hz loop.
constexpr Duration kTick = milliseconds(100);

// MAV_MODE values DO_SET_MODE's param1 is matched against.
constexpr std::uint16_t kMavModeManualDisarmed = 64;
constexpr std::uint16_t kMavModeManualArmed = 192;
constexpr std::uint16_t kMavModeAutoDisarmed = 92;
constexpr std::uint16_t kMavModeAutoArmed = 220;
constexpr std::uint16_t kMavModeStabilizeDisarmed = 80;
constexpr std::uint16_t kMavModeStabilizeArmed = 208;

std::string format(const char* fmt, ...) {
    char buf[64];
    va_list args;
    va_start(args, fmt);
    std::vsnprintf(buf, sizeof buf, fmt, args);
    va_end(args);
    return buf;
}

/// The modes 2.x has (defines.h: MANUAL, LEARNING, STEERING, HOLD, AUTO, RTL, GUIDED, INITIALISING).
bool rover2_has(RoverMode m) {
    switch (m) {
        case RoverMode::Manual:
        case RoverMode::Learning:
        case RoverMode::Steering:
        case RoverMode::Hold:
        case RoverMode::Auto:
        case RoverMode::Rtl:
        case RoverMode::Guided:
        case RoverMode::Initialising:
            return true;
        default:
            return false;
    }
}

/// location_passed_point(): the angle at point2 between point1 and the location, computed on raw
/// latitude/longitude as the firmware does, is over 90 degrees.
bool passed_point(const GeoPoint& location, const GeoPoint& point1, const GeoPoint& point2) {
    const double lx = location.lat - point2.lat;
    const double ly = location.lon - point2.lon;
    const double px = point1.lat - point2.lat;
    const double py = point1.lon - point2.lon;
    if ((lx == 0 && ly == 0) || (px == 0 && py == 0)) {
        return lx == 0 && ly == 0;  // co-located points: passed only when standing on point2
    }
    return lx * px + ly * py < 0;
}

}  // namespace

std::int32_t RoverSim::home_alt_cm() const {
    return static_cast<std::int32_t>(std::lround(config_.home_alt * 100.0));
}

void RoverSim::r2_text(std::uint8_t severity, std::string_view message) {
    mv::Statustext t;
    t.severity = severity;
    mv::set_text(t.text, message);
    out_.send(t);
}

// get_cmd_with_index(): an index past CMD_TOTAL reads as a blank command.
StoredItem RoverSim::r2_cmd(int index) const {
    const int total = static_cast<int>(store_.count()) - 1;
    if (index < 0 || index > total) {
        return rover2_blank();
    }
    return store_.at(static_cast<std::size_t>(index));
}

// send_heartbeat() of GCS_Mavlink.pde: armed whenever not initialising, HOLD reports system status 0.
void RoverSim::r2_send_heartbeat() {
    mv::Heartbeat hb;
    hb.type = mavlink::kMavTypeGroundRover;
    hb.autopilot = mavlink::kMavAutopilotArdupilotmega;
    hb.custom_mode = static_cast<std::uint32_t>(mode_);
    hb.system_status = mavlink::kMavStateActive;
    std::uint8_t base = 0;
    switch (mode_) {
        case RoverMode::Manual:
        case RoverMode::Learning:
        case RoverMode::Steering:
            base = mavlink::kModeFlagManualInputEnabled;
            break;
        case RoverMode::Auto:
        case RoverMode::Rtl:
        case RoverMode::Guided:
            base = mavlink::kModeFlagGuidedEnabled;
            break;
        case RoverMode::Initialising:
            hb.system_status = mavlink::kMavStateCalibrating;
            break;
        case RoverMode::Hold:
            hb.system_status = 0;
            break;
        default:
            break;
    }
    if (mode_ != RoverMode::Initialising) {
        base |= mavlink::kModeFlagSafetyArmed;  // "we are armed if we are not initialising"
    }
    hb.base_mode = base | mavlink::kModeFlagCustomModeEnabled;
    ++counters_.heartbeats_sent;
    out_.send(hb);
}

// The end of startup_ground() (init_commands()) and init_home() once the GPS has a fix: the command index
// is 0, home is written to EEPROM as item 0, next_WP = prev_WP = home.
void RoverSim::r2_boot_ready(TimePoint /*now*/) {
    const TimePoint tick = r2_.next_tick;
    r2_ = Rover2Nav{};
    r2_.next_tick = tick;
    StoredItem home = rover2_blank();
    home.command = kCmdNavWaypoint;
    home.lat_e7 = static_cast<std::int32_t>(std::lround(config_.home.lat * 1e7));
    home.lon_e7 = static_cast<std::int32_t>(std::lround(config_.home.lon * 1e7));
    home.alt = static_cast<float>(home_alt_cm());
    store_.set_home(home);
    r2_.next_wp = home_point();
    r2_.prev_wp = home_point();
}

// set_mode() of system.pde. The same mode again changes nothing; AUTO restarts the mission at item 1
// (restart_nav()); RTL and every other mode the switch does not name, GUIDED included, run do_RTL(), which
// sets RTL (the 2.50 release notes: "When going into GUIDED mode the rover went into RTL - this is fixed").
bool RoverSim::r2_set_mode(RoverMode mode, const std::string& cause, TimePoint now) {
    if (!rover2_has(mode)) {
        return false;
    }
    if (mode == mode_) {
        return true;
    }
    const RoverMode from = mode_;
    const bool navigating = mode == RoverMode::Auto || mode == RoverMode::Rtl || mode == RoverMode::Guided;
    r2_.next_tick = navigating && phase_ == BootPhase::Ready ? now + kTick : kNever;
    switch (mode) {
        case RoverMode::Auto:
            mode_ = mode;
            mode_history_.push_back(ModeChange{
                now, from, mode_, cause, static_cast<std::uint16_t>(r2_.command_index), store_.count()});
            r2_restart_nav(now);
            return true;
        case RoverMode::Rtl:
        case RoverMode::Guided:
            r2_do_rtl(cause, now);
            return true;
        default:
            mode_ = mode;
            mode_history_.push_back(ModeChange{
                now, from, mode_, cause, static_cast<std::uint16_t>(r2_.command_index), store_.count()});
            return true;
    }
}

// do_RTL(): prev_WP = current location, control_mode = RTL, next_WP = home.
void RoverSim::r2_do_rtl(const std::string& cause, TimePoint now) {
    const RoverMode from = mode_;
    r2_.prev_wp = vehicle_.position();
    r2_.next_wp = home_point();
    target_ = r2_.next_wp;
    leg_start_ = r2_.prev_wp;
    mode_ = RoverMode::Rtl;
    if (r2_.next_tick == kNever && phase_ == BootPhase::Ready) {
        r2_.next_tick = now + kTick;
    }
    if (from != mode_) {
        mode_history_.push_back(ModeChange{now, from, mode_, cause,
                                           static_cast<std::uint16_t>(r2_.command_index), store_.count()});
    }
}

// restart_nav() of commands.pde.
void RoverSim::r2_restart_nav(TimePoint now) {
    r2_.prev_wp = vehicle_.position();
    r2_.nav_id = kNoCommand;
    r2_.nav_index = 0;
    r2_process_next_command(now);
}

// process_next_command() of commands_process.pde: makes sure a navigation command is loaded (the next
// item below MAV_CMD_NAV_LAST after the current one), and runs the condition and do-commands that follow
// the previous navigation command, one per call, while the rover heads to the loaded one.
void RoverSim::r2_process_next_command(TimePoint now) {
    const int total = static_cast<int>(store_.count()) - 1;
    std::uint8_t old_index = 0;
    if (r2_.nav_id == kNoCommand) {
        old_index = r2_.nav_index;
        std::uint16_t id = kCmdNavLast;
        StoredItem temp;
        while (id >= kCmdNavLast && r2_.nav_index <= total) {
            ++r2_.nav_index;
            temp = r2_cmd(r2_.nav_index);
            id = temp.command;
        }
        r2_text(kLow, format("Nav command index updated to #%i", static_cast<int>(r2_.nav_index)));
        if (r2_.nav_index > total) {
            // handle_no_commands()
            r2_text(kLow, "No commands - setting HOLD");
            r2_set_mode(RoverMode::Hold, "mission end", now);
        } else {
            r2_.next_nav = temp;
            r2_.nav_id = static_cast<std::uint8_t>(id);
            r2_.non_nav_index = kNoCommand;  // the next intervening non-nav command (if any) is loaded
            r2_.non_nav_id = kNoCommand;
            r2_process_nav_cmd(now);
        }
    }
    if (r2_.non_nav_index == kNoCommand) {
        r2_.non_nav_index = static_cast<std::uint8_t>(old_index + 1);
    } else if (r2_.non_nav_id == kNoCommand) {
        ++r2_.non_nav_index;
    }
    if (r2_.nav_index <= total && r2_.non_nav_id == kNoCommand) {
        const StoredItem temp = r2_cmd(r2_.non_nav_index);
        if (temp.command <= kCmdNavLast) {
            r2_.command_index = r2_.nav_index;
            r2_.non_nav_index = r2_.nav_index;
            r2_.non_nav_id = kWaitCommand;
            r2_text(kLow, format("Non-Nav command ID updated to #%i", static_cast<int>(r2_.non_nav_id)));
        } else {
            r2_.command_index = r2_.non_nav_index;
            r2_.next_nonnav = temp;
            r2_.non_nav_id = static_cast<std::uint8_t>(temp.command);
            r2_text(kLow, format("Non-Nav command ID updated to #%i", static_cast<int>(r2_.non_nav_id)));
            r2_process_non_nav_command(now);
        }
    }
}

// process_nav_cmd() and handle_process_nav_cmd(): TAKEOFF and WAYPOINT drive to the place, RETURN_TO_LAUNCH
// switches to RTL.
void RoverSim::r2_process_nav_cmd(TimePoint now) {
    r2_.non_nav_index = kNoCommand;
    r2_.non_nav_id = kNoCommand;
    r2_text(kLow, format("Executing command ID #%i", static_cast<int>(r2_.next_nav.command & 0xFF)));
    switch (r2_.next_nav.command) {
        case kCmdNavTakeoff:
        case kCmdNavWaypoint:
            r2_set_next_wp(point_of(r2_.next_nav));
            break;
        case kCmdNavReturnToLaunch:
            r2_do_rtl("mission", now);
            break;
        default:
            break;
    }
}

// set_next_WP(): the old target becomes prev_WP, unless the rover is already past the new leg's end.
void RoverSim::r2_set_next_wp(const GeoPoint& wp) {
    r2_.prev_wp = r2_.next_wp;
    r2_.next_wp = wp;
    if (passed_point(vehicle_.position(), r2_.prev_wp, r2_.next_wp)) {
        r2_text(kLow, "Resetting prev_WP");
        r2_.prev_wp = vehicle_.position();
    }
    target_ = r2_.next_wp;
    leg_start_ = r2_.prev_wp;
}

// process_non_nav_command(): a condition waits (verify_condition_command()), a do-command runs at once.
void RoverSim::r2_process_non_nav_command(TimePoint now) {
    const StoredItem& c = r2_.next_nonnav;
    r2_text(kLow, format("Executing command ID #%i", static_cast<int>(c.command & 0xFF)));
    if (r2_.non_nav_id < kCmdConditionLast) {
        switch (c.command) {
            case kCmdConditionDelay:
                r2_.condition_start = now;
                r2_.condition_value = c.lat_e7 * 1000;  // seconds to milliseconds
                break;
            case kCmdConditionDistance:
                r2_.condition_value = c.lat_e7;
                break;
            case kCmdConditionChangeAlt: {
                // get_cmd_with_index() adds home to a relative altitude; the rover stays at home altitude.
                r2_.condition_rate = std::abs(c.lat_e7);
                r2_.condition_value = static_cast<std::int32_t>(c.alt) + (c.frame == 3 ? home_alt_cm() : 0);
                if (r2_.condition_value < home_alt_cm()) {
                    r2_.condition_rate = -r2_.condition_rate;
                }
                break;
            }
            default:
                break;
        }
        return;
    }
    switch (c.command) {
        case kCmdDoJump:
            r2_do_jump(now);
            break;
        case kCmdDoChangeSpeed:
            r2_do_change_speed(now);
            break;
        default:
            break;  // servos, relays, home: nothing a simulated rover shows
    }
    r2_.non_nav_id = kNoCommand;  // "flag command ID so a new one is loaded"
}

// do_jump(): with repeats left, the count is decremented in the stored mission (EEPROM) and the processor
// restarts at the target; -1 jumps forever; anything else does nothing.
void RoverSim::r2_do_jump(TimePoint now) {
    const std::int32_t repeats = r2_.next_nonnav.lat_e7;
    const int target = static_cast<int>(r2_.next_nonnav.param1);
    r2_text(kLow, format("In jump.  Jumps left: %i", static_cast<int>(static_cast<std::int16_t>(repeats))));
    if (repeats <= 0 && repeats != -1) {
        return;
    }
    r2_.nav_id = kNoCommand;
    r2_.next_nav.command = kNoCommand;
    r2_.non_nav_id = kNoCommand;
    if (repeats > 0) {
        const int total = static_cast<int>(store_.count()) - 1;
        const int slot = std::clamp(static_cast<int>(r2_.command_index), 0, total);
        StoredItem jump = r2_cmd(slot);
        jump.lat_e7 = repeats - 1;
        store_.write(static_cast<std::size_t>(slot), jump);
    }
    r2_text(kLow, format("setting command index: %i", target - 1));
    r2_.command_index = target - 1;
    r2_.nav_index = static_cast<std::uint8_t>(target - 1);
    r2_.next_wp =
        r2_.prev_wp;  // "Need to back next_WP up as it was set to the next waypoint following the jump"
    target_ = r2_.next_wp;
    r2_process_next_command(now);
}

// do_change_speed(): speed type 0 only, a whole number of m/s (the stored item keeps param2 as an integer),
// set in RAM (g.speed_cruise.set(), not saved); a throttle above 0 sets CRUISE_THROTTLE the same way.
void RoverSim::r2_do_change_speed(TimePoint now) {
    const StoredItem& c = r2_.next_nonnav;
    const auto speed = static_cast<std::int32_t>(c.alt);
    if (static_cast<int>(c.param1) == 0 && speed > 0) {
        set_unsaved_param("CRUISE_SPEED", static_cast<float>(speed));
        r2_text(kLow, format("Cruise speed: %.1f", static_cast<double>(params_.get("CRUISE_SPEED", 0))));
        note_speed("mission", now, static_cast<std::uint16_t>(r2_.command_index));
    }
    if (c.lat_e7 > 0) {
        set_unsaved_param("CRUISE_THROTTLE", static_cast<float>(c.lat_e7));
        // On the board this number is garbage: the format says %.1f and the argument is an int8_t.
        r2_text(kLow,
                format("Cruise throttle: %.1f", static_cast<double>(params_.get("CRUISE_THROTTLE", 0))));
    }
}

// change_command() of commands_process.pde (MISSION_SET_CURRENT): the index is a uint8_t; a place becomes
// the next target at once in AUTO (update_commands()); otherwise only the command index changes, and
// entering AUTO restarts at item 1 anyway.
void RoverSim::r2_change_command(std::uint16_t seq, TimePoint now) {
    const auto cmd_index = static_cast<std::uint8_t>(seq);
    const StoredItem temp = r2_cmd(cmd_index);
    if (temp.command > kCmdNavLast) {
        r2_text(kLow, "Bad Request - cannot change to non-Nav cmd");
        return;
    }
    r2_text(kLow, format("Received Request - jump to command #%i", static_cast<int>(cmd_index)));
    r2_.nav_id = kNoCommand;
    r2_.next_nav.command = kNoCommand;
    r2_.non_nav_id = kNoCommand;
    r2_.nav_index = static_cast<std::uint8_t>(cmd_index - 1);
    r2_.command_index = cmd_index;
    if (mode_ == RoverMode::Auto && static_cast<int>(store_.count()) - 1 > 1) {
        r2_process_next_command(now);
    }
}

// MISSION_ITEM with current == 2: set_mode(GUIDED) (which ends in RTL, see r2_set_mode), then
// set_guided_WP(): prev_WP = current location, next_WP = the item.
void RoverSim::r2_guided_goto(const StoredItem& item, TimePoint now) {
    r2_do_rtl("command", now);
    r2_.prev_wp = vehicle_.position();
    r2_.next_wp = point_of(item);
    target_ = r2_.next_wp;
    leg_start_ = r2_.prev_wp;
}

// navigate() -> update_navigation() and update_commands(), every 100 ms: in AUTO verify_commands() (is the
// navigation command done, is the condition met) and then process_next_command() when CMD_TOTAL > 1; in RTL
// and GUIDED verify_RTL() and HOLD once home (or the guided point) is reached.
void RoverSim::r2_tick(TimePoint now) {
    if (phase_ != BootPhase::Ready) {
        return;
    }
    switch (mode_) {
        case RoverMode::Auto:
            if (r2_verify_nav(now)) {
                r2_.nav_id = kNoCommand;
            }
            if (r2_verify_condition(now)) {
                r2_.non_nav_id = kNoCommand;
            }
            break;
        case RoverMode::Rtl:
        case RoverMode::Guided:
            if (r2_verify_rtl()) {
                r2_set_mode(RoverMode::Hold, "rtl end", now);
            }
            break;
        default:
            break;
    }
    // update_commands(): only with more than one item after home. With a single item the rover reaches it,
    // nothing loads a next command, and it stays in AUTO driving around that place ("verify_nav: Invalid or
    // no current Nav cmd" every 100 ms).
    if (mode_ == RoverMode::Auto && static_cast<int>(store_.count()) - 1 > 1) {
        r2_process_next_command(now);
    }
}

// verify_nav_command() and verify_nav_wp(): inside WP_RADIUS (and not exactly on it), or past the line
// through the waypoint square to the leg.
bool RoverSim::r2_verify_nav(TimePoint now) {
    switch (r2_.nav_id) {
        case kCmdNavTakeoff:
            return true;  // verify_takeoff()
        case kCmdNavWaypoint: {
            const double distance = distance_m(vehicle_.position(), r2_.next_wp);
            const double radius = params_.get("WP_RADIUS", 2);
            if (distance > 0 && distance <= radius) {
                r2_text(kLow, format("Reached Waypoint #%i dist %um", static_cast<int>(r2_.nav_index),
                                     static_cast<unsigned>(distance)));
                r2_reached(false, distance, now);
                return true;
            }
            if (passed_point(vehicle_.position(), r2_.prev_wp, r2_.next_wp)) {
                r2_text(kLow, format("Passed Waypoint #%i dist %um", static_cast<int>(r2_.nav_index),
                                     static_cast<unsigned>(distance)));
                r2_reached(true, distance, now);
                return true;
            }
            return false;
        }
        case kCmdNavReturnToLaunch:
            return r2_verify_rtl();
        default:
            r2_text(kHigh, "verify_nav: Invalid or no current Nav cmd");
            return false;
    }
}

void RoverSim::r2_reached(bool passed, double distance, TimePoint now) {
    if (config_.reached_style == ReachedStyle::MessageAndText) {
        mv::MissionItemReached r;
        r.seq = r2_.nav_index;
        out_.send(r);
    }
    if (reached_.size() >= kMaxReachedLog) {
        reached_.pop_front();
    }
    ReachedEvent event{now, r2_.nav_index, distance, passed, r2_.next_wp};
    event.command = r2_.next_nav.command;
    take_leg_stats(event);
    reached_.push_back(event);
    ++reached_total_;
}

// verify_condition_command()
bool RoverSim::r2_verify_condition(TimePoint now) {
    switch (r2_.non_nav_id) {
        case kNoCommand:
        case kWaitCommand:
            return false;
        case kCmdConditionDelay:
            if (now - r2_.condition_start > milliseconds(r2_.condition_value)) {
                r2_.condition_value = 0;
                return true;
            }
            return false;
        case kCmdConditionDistance:
            if (distance_m(vehicle_.position(), r2_.next_wp) < r2_.condition_value) {
                r2_.condition_value = 0;
                return true;
            }
            return false;
        case kCmdConditionChangeAlt: {
            const std::int32_t alt = home_alt_cm();
            if ((r2_.condition_rate >= 0 && alt >= r2_.condition_value) ||
                (r2_.condition_rate <= 0 && alt <= r2_.condition_value)) {
                r2_.condition_value = 0;
                return true;
            }
            return false;
        }
        default:
            r2_text(kHigh, "verify_conditon: Invalid or no current Condition cmd");
            return false;
    }
}

// verify_RTL()
bool RoverSim::r2_verify_rtl() {
    const double distance = distance_m(vehicle_.position(), r2_.next_wp);
    if (distance <= params_.get("WP_RADIUS", 2)) {
        r2_text(kLow, "Reached home");
        return true;
    }
    if (passed_point(vehicle_.position(), r2_.prev_wp, r2_.next_wp)) {
        r2_text(kLow, format("Reached Home dist %um", static_cast<unsigned>(distance)));
        return true;
    }
    return false;
}

// MAVLINK_MSG_ID_SET_MODE of GCS_Mavlink.pde: no target check, no acknowledgement, custom modes MANUAL,
// HOLD, LEARNING, STEERING, AUTO and RTL only.
void RoverSim::r2_on_set_mode(const mv::Frame& f, TimePoint now) {
    const auto m = mv::decode_payload<mv::SetMode>(f.payload_view());
    if ((m.base_mode & mavlink::kModeFlagCustomModeEnabled) == 0) {
        return;  // "we ignore base_mode as there is no sane way to map from that bitmap"
    }
    const auto mode = mode_from_number(m.custom_mode);
    if (!mode) {
        return;
    }
    switch (*mode) {
        case RoverMode::Manual:
        case RoverMode::Hold:
        case RoverMode::Learning:
        case RoverMode::Steering:
        case RoverMode::Auto:
        case RoverMode::Rtl:
            r2_set_mode(*mode, "command", now);
            return;
        default:
            return;
    }
}

// MAVLINK_MSG_ID_COMMAND_LONG of GCS_Mavlink.pde.
void RoverSim::r2_on_command_long(const mv::Frame& f, TimePoint now) {
    const auto c = mv::decode_payload<mv::CommandLong>(f.payload_view());
    if (!addressed(c.target_system)) {
        return;
    }
    r2_text(kLow, "command received: ");
    std::uint8_t result = mavlink::kResultUnsupported;
    switch (c.command) {
        case kCmdNavReturnToLaunch:
            r2_set_mode(RoverMode::Rtl, "command", now);
            result = mavlink::kResultAccepted;
            break;
        case mavlink::kCmdMissionStart:
            r2_set_mode(RoverMode::Auto, "command", now);  // with no mission: AUTO, then HOLD
            result = mavlink::kResultAccepted;
            break;
        case mavlink::kCmdPreflightCalibration:
            result = mavlink::kResultAccepted;  // the INS and radio trims are not simulated
            break;
        case mavlink::kCmdDoSetMode:
            // param1 is a MAV_MODE (base mode), not a custom mode.
            switch (static_cast<std::uint16_t>(c.param1)) {
                case kMavModeManualArmed:
                case kMavModeManualDisarmed:
                    r2_set_mode(RoverMode::Manual, "command", now);
                    result = mavlink::kResultAccepted;
                    break;
                case kMavModeAutoArmed:
                case kMavModeAutoDisarmed:
                    r2_set_mode(RoverMode::Auto, "command", now);
                    result = mavlink::kResultAccepted;
                    break;
                case kMavModeStabilizeDisarmed:
                case kMavModeStabilizeArmed:
                    r2_set_mode(RoverMode::Learning, "command", now);
                    result = mavlink::kResultAccepted;
                    break;
                default:
                    result = mavlink::kResultUnsupported;
                    break;
            }
            break;
        case mavlink::kCmdDoSetServo:
            result = mavlink::kResultAccepted;
            break;
        case mavlink::kCmdPreflightRebootShutdown:
            if (c.param1 == 1) {
                reboot(now);  // reboot_apm() does not return: no COMMAND_ACK
                return;
            }
            break;
        default:
            break;
    }
    mv::CommandAck ack;
    ack.command = c.command;
    ack.result = result;
    ack.target_system = f.sysid;
    ack.target_component = f.compid;
    out_.reply(ack);
}

}  // namespace airseg::apmsim
