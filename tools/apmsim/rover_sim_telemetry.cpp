// RoverSim: heartbeats and the telemetry messages of the stream groups.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

namespace {

// Sensors an APM 2.5 reports (gyro, accel, mag, baro, GPS, motor outputs, RC receiver).
constexpr std::uint32_t kSensors = 0x1 | 0x2 | 0x4 | 0x8 | 0x20 | 0x8000 | 0x10000;

double to_deg(double rad) {
    return rad * 180.0 / std::numbers::pi;
}

std::int32_t e7(double deg) {
    return static_cast<std::int32_t>(std::lround(deg * 1e7));
}

}  // namespace

void RoverSim::send_heartbeat(TimePoint now) {
    if (now < hb_stall_until_) {
        ++counters_.heartbeats_stalled;
        return;
    }
    if (rover2_telemetry()) {
        r2_send_heartbeat();
        return;
    }
    mv::Heartbeat hb;
    hb.type = mavlink::kMavTypeGroundRover;
    hb.autopilot = mavlink::kMavAutopilotArdupilotmega;
    hb.custom_mode = static_cast<std::uint32_t>(mode_);
    hb.base_mode = mavlink::kModeFlagCustomModeEnabled;
    switch (mode_) {
        case RoverMode::Manual:
        case RoverMode::Learning:
        case RoverMode::Acro:
            hb.base_mode |= mavlink::kModeFlagManualInputEnabled;
            break;
        case RoverMode::Steering:
            hb.base_mode |= mavlink::kModeFlagManualInputEnabled | mavlink::kModeFlagStabilizeEnabled;
            break;
        case RoverMode::Auto:
        case RoverMode::Rtl:
        case RoverMode::SmartRtl:
        case RoverMode::Guided:
            hb.base_mode |= mavlink::kModeFlagAutoEnabled | mavlink::kModeFlagGuidedEnabled |
                            mavlink::kModeFlagStabilizeEnabled;
            break;
        case RoverMode::Hold:
        case RoverMode::Loiter:
        case RoverMode::Initialising:
            break;
    }
    // GCS_MAVLINK_Rover::base_mode() and vehicle_system_status(): armed is never shown while initialising;
    // the status follows the mode, not the arming (CALIBRATING while initialising, STANDBY in HOLD, ACTIVE
    // otherwise, disarmed or not).
    if (is_armed() && mode_ != RoverMode::Initialising) {
        hb.base_mode |= mavlink::kModeFlagSafetyArmed;
    }
    if (phase_ == BootPhase::Calibrating || mode_ == RoverMode::Initialising) {
        hb.system_status = mavlink::kMavStateCalibrating;
    } else {
        hb.system_status = mode_ == RoverMode::Hold ? mavlink::kMavStateStandby : mavlink::kMavStateActive;
    }
    ++counters_.heartbeats_sent;
    out_.send(hb);
}

void RoverSim::send_mission_current() {
    mv::MissionCurrent m;
    if (rover2_telemetry()) {
        m.seq = static_cast<std::uint16_t>(r2_.command_index);  // send_current_waypoint(): g.command_index
        out_.send(m);
        return;
    }
    m.seq = current_seq_;
    m.total = static_cast<std::uint16_t>(store_.count() - 1);
    // MISSION_STATE: 1 no mission, 2 not started, 3 active, 4 paused, 5 complete.
    if (store_.count() <= 1) {
        m.mission_state = 1;
    } else if (mission_complete_) {
        m.mission_state = 5;
    } else if (mission_running_ && mode_ == RoverMode::Auto) {
        m.mission_state = 3;
    } else {
        m.mission_state = current_seq_ == 0 ? 2 : 4;
    }
    out_.send(m);
}

void RoverSim::send_home_position() {
    mv::HomePosition h;
    h.latitude = e7(config_.home.lat);
    h.longitude = e7(config_.home.lon);
    h.altitude = static_cast<std::int32_t>(std::lround(config_.home_alt * 1000.0));
    h.q = {1.0F, 0.0F, 0.0F, 0.0F};
    h.time_usec = unix_us(now_);
    out_.reply(h);
}

void RoverSim::send_autopilot_version() {
    mv::AutopilotVersion v;
    // MISSION_FLOAT | PARAM_FLOAT | MISSION_INT | SET_POSITION_TARGET_GLOBAL_INT, and MAVLINK2 when spoken.
    v.capabilities = 0x1 | 0x2 | 0x4 | 0x100;
    if (config_.version == mv::Version::V2) {
        v.capabilities |= 0x2000;
    }
    v.flight_sw_version = (2U << 24) | (51U << 16) | (0U << 8) | 255U;  // 2.51 official
    v.uid = config_.seed;
    out_.reply(v);
}

void RoverSim::send_stream_message(std::uint32_t msgid, TimePoint now) {
    const GeoPoint pos = vehicle_.position();
    const double heading_deg = to_deg(vehicle_.heading());
    const double speed = vehicle_.speed();
    const double capacity = std::max(1.0F, params_.get("BATT_CAPACITY", 3300));
    const double used = std::clamp(consumed_mah_ / capacity, 0.0, 1.0);
    const double volts = 12.6 - 2.0 * used;  // a 3S LiPo from full to nearly flat
    const double amps = 1.5 + 10.0 * std::abs(vehicle_.throttle());
    const auto remaining = static_cast<std::int8_t>(std::lround(100.0 * (1.0 - used)));
    const auto servo = [](double v) { return static_cast<std::uint16_t>(1500 + std::lround(400 * v)); };
    if (rover2_telemetry()) {
        // GCS_Mavlink.pde of 2.43 streams no SYSTEM_TIME, BATTERY_STATUS or RC_CHANNELS, and no
        // NAV_CONTROLLER_OUTPUT in MANUAL.
        if (msgid == mv::SystemTime::kId || msgid == mv::BatteryStatus::kId || msgid == mv::RcChannels::kId ||
            (msgid == mv::NavControllerOutput::kId && mode_ == RoverMode::Manual)) {
            return;
        }
    }

    switch (msgid) {
        case mv::SysStatus::kId: {
            mv::SysStatus s;
            s.onboard_control_sensors_present = kSensors;
            s.onboard_control_sensors_enabled = kSensors;
            s.onboard_control_sensors_health = kSensors;
            s.load = 420;
            s.voltage_battery = static_cast<std::uint16_t>(std::lround(volts * 1000));
            s.current_battery = static_cast<std::int16_t>(std::lround(amps * 100));
            s.battery_remaining = remaining;
            s.drop_rate_comm = 0;
            out_.send(s);
            return;
        }
        case mv::MissionCurrent::kId:
            send_mission_current();
            return;
        case mv::GpsRawInt::kId: {
            mv::GpsRawInt g;
            g.time_usec = unix_us(now);
            g.fix_type = gps_fix_ ? 3 : 1;  // 1: GPS_FIX_TYPE_NO_FIX
            g.lat = e7(pos.lat);
            g.lon = e7(pos.lon);
            g.alt = static_cast<std::int32_t>(std::lround(config_.home_alt * 1000.0));
            g.eph = 121;
            g.epv = 200;
            g.vel = static_cast<std::uint16_t>(std::lround(std::abs(speed) * 100));
            g.cog = static_cast<std::uint16_t>(std::lround(heading_deg * 100) % 36000);
            g.satellites_visible = gps_fix_ ? 10 : 0;
            out_.send(g);
            return;
        }
        case mv::NavControllerOutput::kId: {
            mv::NavControllerOutput n;
            if (target_) {
                const auto b = static_cast<std::int16_t>(std::lround(to_deg(bearing_rad(pos, *target_))));
                n.nav_bearing = b;
                n.target_bearing = b;
                n.wp_dist =
                    static_cast<std::uint16_t>(std::min(65535.0, std::round(distance_m(pos, *target_))));
            }
            out_.send(n);
            return;
        }
        case mv::GlobalPositionInt::kId: {
            mv::GlobalPositionInt g;
            g.time_boot_ms = time_boot_ms(now);
            g.lat = e7(pos.lat);
            g.lon = e7(pos.lon);
            g.alt = static_cast<std::int32_t>(std::lround(config_.home_alt * 1000.0));
            g.relative_alt = 0;
            g.vx = static_cast<std::int16_t>(std::lround(speed * std::cos(vehicle_.heading()) * 100));
            g.vy = static_cast<std::int16_t>(std::lround(speed * std::sin(vehicle_.heading()) * 100));
            g.hdg = static_cast<std::uint16_t>(std::lround(heading_deg * 100) % 36000);
            out_.send(g);
            return;
        }
        case mv::Attitude::kId: {
            mv::Attitude a;
            a.time_boot_ms = time_boot_ms(now);
            const double yaw = vehicle_.heading() > std::numbers::pi
                                   ? vehicle_.heading() - 2 * std::numbers::pi
                                   : vehicle_.heading();
            a.yaw = static_cast<float>(yaw);
            a.yawspeed = static_cast<float>(vehicle_.turn_rate());
            out_.send(a);
            return;
        }
        case mv::VfrHud::kId: {
            mv::VfrHud v;
            v.airspeed = static_cast<float>(speed);
            v.groundspeed = static_cast<float>(std::abs(speed));
            v.heading = static_cast<std::int16_t>(std::lround(heading_deg) % 360);
            v.throttle = static_cast<std::uint16_t>(std::lround(std::abs(vehicle_.throttle()) * 100));
            v.alt = config_.home_alt;
            out_.send(v);
            return;
        }
        case mv::RcChannelsRaw::kId: {
            mv::RcChannelsRaw r;
            r.time_boot_ms = time_boot_ms(now);
            r.chan1_raw = rc_input(1, now);
            r.chan2_raw = rc_input(2, now);
            r.chan3_raw = rc_input(3, now);
            r.chan4_raw = rc_input(4, now);
            r.chan5_raw = rc_input(5, now);
            r.chan6_raw = rc_input(6, now);
            r.chan7_raw = rc_input(7, now);
            r.chan8_raw = rc_input(8, now);
            r.rssi = 255;
            out_.send(r);
            return;
        }
        case mv::RcChannels::kId: {
            mv::RcChannels r;
            r.time_boot_ms = time_boot_ms(now);
            r.chancount = 8;
            r.chan1_raw = rc_input(1, now);
            r.chan2_raw = rc_input(2, now);
            r.chan3_raw = rc_input(3, now);
            r.chan4_raw = rc_input(4, now);
            r.chan5_raw = rc_input(5, now);
            r.chan6_raw = rc_input(6, now);
            r.chan7_raw = rc_input(7, now);
            r.chan8_raw = rc_input(8, now);
            r.rssi = 255;
            out_.send(r);
            return;
        }
        case mv::ServoOutputRaw::kId: {
            mv::ServoOutputRaw s;
            s.time_usec = time_boot_ms(now) * 1000U;
            s.servo1_raw = servo(vehicle_.steering());
            s.servo3_raw = servo(vehicle_.throttle());
            out_.send(s);
            return;
        }
        case mv::SystemTime::kId: {
            mv::SystemTime t;
            t.time_unix_usec = unix_us(now);
            t.time_boot_ms = time_boot_ms(now);
            out_.send(t);
            return;
        }
        case mv::BatteryStatus::kId: {
            mv::BatteryStatus b;
            b.type = 1;  // MAV_BATTERY_TYPE_LIPO
            b.temperature = INT16_MAX;
            b.voltages.fill(UINT16_MAX);
            b.voltages[0] = static_cast<std::uint16_t>(std::lround(volts * 1000));
            b.current_battery = static_cast<std::int16_t>(std::lround(amps * 100));
            b.current_consumed = static_cast<std::int32_t>(std::lround(consumed_mah_));
            b.energy_consumed = -1;
            b.battery_remaining = remaining;
            out_.send(b);
            return;
        }
        default:
            return;
    }
}

}  // namespace airseg::apmsim
