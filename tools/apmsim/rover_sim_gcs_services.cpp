// RoverSim: what modern ArduPilot serves a ground station besides parameters, missions and COMMAND_LONG:
// COMMAND_INT (MAV_CMD_DO_REPOSITION as GCS_MAVLINK_Rover::handle_command_int_do_reposition(), the rest as
// their COMMAND_LONG form), SET_POSITION_TARGET_GLOBAL_INT (a position in GUIDED, as ArduPilot's "Rover
// Commands in Guided Mode" documents it), TIMESYNC (GCS_MAVLINK::handle_timesync()) and MAVLink FTP
// (ftp_server.hpp). APMrover2 2.4x knows none of them: its board ignores them.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

namespace {

constexpr std::uint16_t kCmdDoReposition = 192;
constexpr int kRepositionChangeMode = 1;           // MAV_DO_REPOSITION_FLAGS_CHANGE_MODE, in param2
constexpr float kLocationAltMaxM = 83000.0F;       // LOCATION_ALT_MAX_M: what a Location's altitude can hold
constexpr std::uint16_t kPositionIgnored = 0b111;  // POSITION_TARGET_TYPEMASK X_IGNORE | Y_IGNORE | Z_IGNORE

/// The frames mavlink_coordinate_frame_to_location_alt_frame() turns into a Location's altitude frame.
bool global_frame(std::uint8_t frame) {
    switch (frame) {
        case mv::kFrameGlobal:
        case mv::kFrameGlobalRelativeAlt:
        case mv::kFrameGlobalInt:
        case mv::kFrameGlobalRelativeAltInt:
        case 10:  // MAV_FRAME_GLOBAL_TERRAIN_ALT
        case 11:  // MAV_FRAME_GLOBAL_TERRAIN_ALT_INT
            return true;
        default:
            return false;
    }
}

}  // namespace

void RoverSim::on_command_int(const mv::Frame& f, TimePoint now) {
    if (rover2_commands()) {
        ++counters_.frames_ignored;
        return;
    }
    const auto c = mv::decode_payload<mv::CommandInt>(f.payload_view());
    if (!addressed(c.target_system)) {
        return;
    }
    if (c.command != kCmdDoReposition) {
        mv::CommandLong as_long;
        as_long.target_system = c.target_system;
        as_long.target_component = c.target_component;
        as_long.command = c.command;
        as_long.param1 = c.param1;
        as_long.param2 = c.param2;
        as_long.param3 = c.param3;
        as_long.param4 = c.param4;
        as_long.param5 = static_cast<float>(c.x);
        as_long.param6 = static_cast<float>(c.y);
        as_long.param7 = c.z;
        on_command(as_long, f, now);
        return;
    }
    mv::CommandAck ack;
    ack.command = c.command;
    ack.result = do_reposition(c, now);
    ack.target_system = f.sysid;
    ack.target_component = f.compid;
    out_.reply(ack);
}

std::uint8_t RoverSim::do_reposition(const mv::CommandInt& c, TimePoint now) {
    if (phase_ != BootPhase::Ready) {
        return mv::kResultTemporarilyRejected;
    }
    const bool change_mode = (static_cast<std::int32_t>(c.param2) & kRepositionChangeMode) != 0;
    const bool guided = mode_ == RoverMode::Guided;
    if (!guided && !change_mode) {
        return mv::kResultDenied;
    }
    // check_latlng(), the null island test, then location_from_command_t(): a global frame, an altitude a
    // Location holds.
    if (std::abs(c.x) > 900'000'000 || std::abs(c.y) > 1'800'000'000 || (c.x == 0 && c.y == 0)) {
        return mv::kResultDenied;
    }
    if (!global_frame(c.frame) || !std::isfinite(c.z) || std::fabs(c.z) > kLocationAltMaxM) {
        return mv::kResultDenied;
    }
    if (!guided && !set_mode(RoverMode::Guided, "command", now)) {
        return mv::kResultFailed;
    }
    if (c.param1 > 0) {
        speed_override_ = std::max(0.05, static_cast<double>(c.param1));  // AR_WPNav's least speed
        note_speed("command", now);
    }
    StoredItem target;
    target.lat_e7 = c.x;
    target.lon_e7 = c.y;
    target.alt = c.z;
    target.frame = c.frame;
    return guided_goto(target) ? mv::kResultAccepted : mv::kResultFailed;
}

// In GUIDED only, in a global frame, and with a position: the rover drives to it (a position given makes
// ArduPilot ignore the velocity, yaw and yaw rate). A target alone as velocity or yaw is not simulated, and
// is ignored as a target outside GUIDED is. No answer either way: a station watches
// POSITION_TARGET_GLOBAL_INT or the vehicle to see it took effect.
void RoverSim::on_set_position_target(const mv::Frame& f) {
    if (rover2_commands()) {
        ++counters_.frames_ignored;
        return;
    }
    const auto m = mv::decode_payload<mv::SetPositionTargetGlobalInt>(f.payload_view());
    if (!addressed(m.target_system)) {
        return;
    }
    const bool position = (m.type_mask & kPositionIgnored) != kPositionIgnored;
    // check_latlng(): the position within the globe's ranges.
    if (phase_ != BootPhase::Ready || mode_ != RoverMode::Guided || !global_frame(m.coordinate_frame) ||
        !position || std::abs(m.lat_int) > 900'000'000 || std::abs(m.lon_int) > 1'800'000'000) {
        ++counters_.frames_ignored;
        return;
    }
    StoredItem target;
    target.lat_e7 = m.lat_int;
    target.lon_e7 = m.lon_int;
    target.alt = m.alt;
    target.frame = m.coordinate_frame;
    if (!guided_goto(target)) {
        ++counters_.frames_ignored;
    }
}

void RoverSim::on_timesync(const mv::Frame& f, TimePoint now) {
    if (rover2_commands()) {
        ++counters_.frames_ignored;
        return;
    }
    const auto m = mv::decode_payload<mv::Timesync>(f.payload_view());
    if (m.tc1 != 0) {
        return;  // an answer to someone's request, not a request
    }
    mv::Timesync reply;
    // AP_HAL::micros64() * 1000: the board's time since boot, in nanoseconds at microsecond resolution.
    reply.tc1 = std::chrono::duration_cast<microseconds>(now - boot_started_).count() * 1000;
    reply.ts1 = m.ts1;
    reply.target_system = f.sysid;
    reply.target_component = f.compid;
    out_.reply(reply);
}

void RoverSim::on_ftp(const mv::Frame& f) {
    if (rover2_commands()) {
        ++counters_.frames_ignored;
        return;
    }
    const auto m = mv::decode_payload<mv::FileTransferProtocol>(f.payload_view());
    if (!addressed(m.target_system)) {
        return;
    }
    for (const auto& packet : ftp_.handle(ftp::decode(m.payload))) {
        mv::FileTransferProtocol reply;
        reply.target_system = f.sysid;
        reply.target_component = f.compid;
        reply.payload = ftp::encode(packet);
        out_.reply(reply);
    }
}

}  // namespace airseg::apmsim
