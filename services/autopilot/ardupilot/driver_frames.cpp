// Driver: what comes from the autopilot (heartbeats, telemetry, texts, reboots, link loss).
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>

#include "services/autopilot/ardupilot/driver.hpp"
#include "services/autopilot/ardupilot/rover_modes.hpp"
#include "services/autopilot/ardupilot/telemetry_check.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/enums.hpp"
#include "services/common/printable.hpp"

namespace airseg::autopilot::ardupilot {

namespace mav = airseg::mavlink;

namespace {
constexpr Duration kSameReached = seconds(3);  // the item-reached message and the text for the same slot

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); });
    return out;
}
}  // namespace

void Driver::tap_incoming(const mav::Frame& f) {
    if (!tap_) {
        return;
    }
    if (const auto bytes = mav::reencode(f); !bytes.empty()) {
        tap_(false, bytes);
    }
}

void Driver::on_frame(const mav::Frame& f, TimePoint now) {
    if (f.sysid != config_.target_sysid) {
        return;
    }
    link_.on_frame();
    missions_.handle_frame(f, now);
    params_.handle_frame(f, now);
    const auto p = f.payload_view();
    switch (f.msgid) {
        case mav::Heartbeat::kId:
            if (f.compid == config_.target_compid) {
                on_heartbeat(mav::decode_payload<mav::Heartbeat>(p), now);
            }
            break;
        case mav::Statustext::kId:
            on_statustext(mav::decode_payload<mav::Statustext>(p), now);
            break;
        case mav::SystemTime::kId:
            on_time_boot(mav::decode_payload<mav::SystemTime>(p).time_boot_ms, now);
            break;
        case mav::GlobalPositionInt::kId: {
            const auto m = mav::decode_payload<mav::GlobalPositionInt>(p);
            on_position("GLOBAL_POSITION_INT", m.lat, m.lon, m.alt);
            telemetry_.relative_alt = m.relative_alt * 1e-3;
            if (m.hdg != 65535) {
                telemetry_.heading = m.hdg * 0.01;
            }
            on_time_boot(m.time_boot_ms, now);
            break;
        }
        case mav::Attitude::kId: {
            // A NaN or infinite angle is not taken: the field keeps its last number.
            const auto m = mav::decode_payload<mav::Attitude>(p);
            take_float("ATTITUDE.roll", m.roll, telemetry_.roll);
            take_float("ATTITUDE.pitch", m.pitch, telemetry_.pitch);
            take_float("ATTITUDE.yaw", m.yaw, telemetry_.yaw);
            break;
        }
        case mav::VfrHud::kId: {
            const auto m = mav::decode_payload<mav::VfrHud>(p);
            take_float("VFR_HUD.groundspeed", m.groundspeed, telemetry_.ground_speed);
            telemetry_.heading = (m.heading % 360 + 360) % 360;
            break;
        }
        case mav::GpsRawInt::kId: {
            const auto m = mav::decode_payload<mav::GpsRawInt>(p);
            telemetry_.gps_fix = m.fix_type <= 6 ? static_cast<GpsFix>(m.fix_type) : GpsFix::RtkFixed;
            telemetry_.satellites = m.satellites_visible == 255 ? 0 : m.satellites_visible;
            gps_fix_type_ = m.fix_type;
            if (!gives_position(m.fix_type)) {
                invalidate_position("no GPS fix (GPS_RAW_INT fix_type " + std::to_string(m.fix_type) + ")");
            } else if (!telemetry_.position) {
                on_position("GPS_RAW_INT", m.lat, m.lon, m.alt);
            }
            break;
        }
        case mav::SysStatus::kId: {
            const auto m = mav::decode_payload<mav::SysStatus>(p);
            if (m.voltage_battery != 65535) {
                telemetry_.battery_voltage = m.voltage_battery * 1e-3;
            }
            if (m.current_battery >= 0) {
                telemetry_.battery_current = m.current_battery * 1e-2;
            }
            if (m.battery_remaining >= 0) {
                telemetry_.battery_remaining = m.battery_remaining;
            }
            break;
        }
        case mav::HomePosition::kId: {
            const auto m = mav::decode_payload<mav::HomePosition>(p);
            if (const auto why = position_problem(m.latitude, m.longitude); why.empty()) {
                telemetry_.home = Position{m.latitude * 1e-7, m.longitude * 1e-7, m.altitude * 1e-3};
            } else if (m.latitude != 0 || m.longitude != 0) {
                refuse_value("HOME_POSITION: " + why);  // the home kept is the last valid one
            }
            break;
        }
        case mav::MissionCurrent::kId:
            on_mission_current(mav::decode_payload<mav::MissionCurrent>(p).seq, now);
            break;
        case mav::MissionItemReached::kId:
            on_reached(mav::decode_payload<mav::MissionItemReached>(p).seq, now);
            break;
        case mav::CommandAck::kId:
            on_command_ack(mav::decode_payload<mav::CommandAck>(p), now);
            break;
        default:
            break;
    }
}

// A position reaches the telemetry only when it is a place and comes with a fix; otherwise the telemetry has
// none, and says why.
void Driver::on_position(const char* message, std::int32_t lat_e7, std::int32_t lon_e7, std::int32_t alt_mm) {
    if (const auto why = position_problem(lat_e7, lon_e7); !why.empty()) {
        if (lat_e7 != 0 || lon_e7 != 0) {
            refuse_value(std::string(message) + ": " + why);
        }
        invalidate_position(why);
        return;
    }
    if (gps_fix_type_ && !gives_position(*gps_fix_type_)) {
        invalidate_position("no GPS fix (GPS_RAW_INT fix_type " + std::to_string(*gps_fix_type_) + ")");
        return;
    }
    telemetry_.position = Position{lat_e7 * 1e-7, lon_e7 * 1e-7, alt_mm * 1e-3};
    telemetry_.position_invalid.clear();
}

void Driver::invalidate_position(std::string why) {
    telemetry_.position.reset();
    telemetry_.position_invalid = std::move(why);
}

void Driver::take_float(const char* where, float value, double& field) {
    if (auto why = float_problem(where, value); !why.empty()) {
        refuse_value(std::move(why));
        return;
    }
    field = value;
}

void Driver::refuse_value(std::string why) {
    ++refused_values_;
    refused_value_ = std::move(why);
}

void Driver::on_heartbeat(const mav::Heartbeat& hb, TimePoint now) {
    system_status_ = hb.system_status;
    armed_ = (hb.base_mode & mavlink::kModeFlagSafetyArmed) != 0;
    armed_seen_ = true;
    // APM:Rover 2.x reports MAV_STATE_UNINIT in HOLD (send_heartbeat() of its GCS_Mavlink.pde): in a running
    // mode UNINIT is that quirk, not a board starting up.
    const bool uninit_booting = hb.system_status == mavlink::kMavStateUninit &&
                                hb.custom_mode != static_cast<std::uint32_t>(RoverMode::Hold);
    const bool booting = uninit_booting || hb.system_status == mavlink::kMavStateBoot ||
                         hb.system_status == mavlink::kMavStateCalibrating ||
                         hb.custom_mode == static_cast<std::uint32_t>(RoverMode::Initialising);
    constexpr auto kBootMode = static_cast<std::uint32_t>(RoverMode::Initialising);
    const std::string left_for_boot =
        mode_ && *mode_ != kBootMode && hb.custom_mode == kBootMode ? rover_mode_name(*mode_) : std::string{};
    const auto seen = link_.on_heartbeat(now, booting, watching_for_reboots(), left_for_boot);
    if (seen.came_up) {
        emit(LinkUp{});
        if (phase_ == Phase::Ready) {
            request_streams();  // the autopilot may have lost them in a reboot we cannot prove
        }
    }
    if (seen.reboot) {
        reboot_detected(*seen.reboot, now);
    }
    const bool mode_changed = !mode_ || *mode_ != hb.custom_mode;
    mode_ = hb.custom_mode;
    if (auto o = modes_.on_heartbeat(hb.custom_mode)) {
        finish_mode(std::move(*o), now);
    } else if (mode_changed) {
        override_active_ = false;  // the RC pilot or the autopilot took over
    }
    if (auto o = arming_.on_heartbeat(armed_)) {
        state_done(o->id, o->result, std::move(o->detail));
    }
    if (phase_ == Phase::WaitBoot && !booting && hb.system_status != mavlink::kMavStatePoweroff) {
        enter(Phase::Params, now);
    }
    update_state(now, false);
    if (hb.custom_mode == static_cast<std::uint32_t>(RoverMode::Auto)) {
        if (mode_changed) {
            if (!auto_check_.active()) {
                auto_check_.arm(board_slot(), now);  // entered AUTO without our asking
            }
            auto_check_.on_auto(now);
            on_auto_entered();  // the board's speed is its own again
            update_speed(now);
        }
    } else if (mode_changed) {
        auto_check_.cancel();
    }
}

void Driver::on_mission_current(std::uint16_t seq, TimePoint now) {
    telemetry_.mission_current = seq;
    switch (auto_check_.on_current(seq, now)) {
        case AutoEntryCheck::Verdict::Report:
            report_current(seq);
            if (!mission_.empty() && seq > mission_.size()) {
                restore_board_speed(now);  // a Stop sent as a jump past the end has run: the plan's end
            } else {
                update_speed(now);
            }
            break;
        case AutoEntryCheck::Verdict::Suppress:
            break;
        case AutoEntryCheck::Verdict::Correct:
            // The board restarted its mission on entering AUTO: back to the slot it was at. The completion
            // is the driver's own (no requester waits for it).
            (void)missions_.set_current(*auto_check_.expected(), now);
            break;
    }
}

// The slot the board heads for: its last MISSION_CURRENT, or, when it has since reported that slot reached
// (its MISSION_CURRENT may come only with the telemetry stream, as on APM:Rover 2.x), the next place in the
// mission after it, jumps followed.
std::uint16_t Driver::board_slot() const {
    if (!current_reached_) {
        return reported_current_;
    }
    std::size_t slot = reported_current_ + 1u;
    for (std::size_t hops = 0; slot >= 1 && slot <= mission_.size() && hops <= mission_.size(); ++hops) {
        const MissionItem& item = mission_[slot - 1];
        if (item.kind != MissionItem::Kind::JumpTo) {
            return static_cast<std::uint16_t>(slot);
        }
        slot = item.jump_slot;
    }
    return reported_current_;
}

void Driver::report_current(std::uint16_t seq) {
    if (seq != reported_current_) {
        reported_current_ = seq;
        current_reached_ = false;
        emit(MissionCurrentChanged{seq});
    }
}

void Driver::on_statustext(const mav::Statustext& t, TimePoint now) {
    // Escaped here, at the edge: the text goes on to logs, events for the ground and JSON.
    const std::string text = printable(mav::text_of(t.text));
    emit(StatusText{t.severity, text});
    arming_.on_text(text, now);
    const std::string l = lower(text);
    if (const auto pos = l.find("reached waypoint #"); pos != std::string::npos) {
        const char* digits = l.c_str() + pos + 18;
        char* end = nullptr;
        const unsigned long seq = std::strtoul(digits, &end, 10);
        if (end != digits && seq <= 65535) {
            on_reached(static_cast<std::uint16_t>(seq), now);
        }
    }
}

void Driver::on_time_boot(std::uint32_t time_boot_ms, TimePoint now) {
    if (auto evidence = link_.on_time_boot(time_boot_ms, now, watching_for_reboots())) {
        reboot_detected(*evidence, now);
    }
}

void Driver::on_command_ack(const mav::CommandAck& ack, TimePoint now) {
    if (!out_.addressed_to_us(ack.target_system, ack.target_component)) {
        return;  // a ground station's command, answered to it
    }
    if (ack.command == mavlink::kCmdDoChangeSpeed) {
        on_speed_ack(ack.result, now);
        return;
    }
    if (ack.command == mavlink::kCmdComponentArmDisarm) {
        arming_.on_ack(ack.result, now);  // the heartbeat confirms, or the refusal's texts follow
        return;
    }
    if (ack.command != mavlink::kCmdDoSetMode) {
        return;
    }
    if (auto o = modes_.on_ack(ack.result)) {
        finish_mode(std::move(*o), now);
    }
}

void Driver::on_reached(std::uint16_t seq, TimePoint now) {
    if (last_reached_ && last_reached_->first == seq && now - last_reached_->second < kSameReached) {
        return;  // the same event by its second route
    }
    last_reached_ = std::pair{seq, now};
    auto_check_.on_reached(seq);
    current_reached_ = seq == reported_current_;
    if (seq >= 1 && seq <= mission_.size() && mission_[seq - 1u].kind == MissionItem::Kind::Stop) {
        restore_board_speed(now);  // the plan's end
    }
    emit(WaypointReached{seq});
}

void Driver::reboot_detected(const std::string& evidence, TimePoint now) {
    ++reboots_;
    auto_check_.cancel();
    forget_speed();
    armed_seen_ = false;
    emit(AutopilotRebooted{evidence});
    cancel_everything("autopilot rebooted", now);
    last_error_ = "autopilot rebooted: " + evidence;
    enter(Phase::WaitBoot, now);
}

void Driver::link_lost(Duration silent, const std::string& detail, TimePoint now) {
    const auto silent_s = std::chrono::duration<double>(silent).count();
    emit(LinkDown{"no heartbeat for " + std::to_string(static_cast<int>(silent_s)) + " s (" + detail + ")"});
    // Transfers in progress are left to their own timeouts: a few lost heartbeats on a noisy radio must not
    // throw away a long upload that is still making progress.
    update_state(now, false);
}

}  // namespace airseg::autopilot::ardupilot
