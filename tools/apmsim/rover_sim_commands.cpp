// RoverSim: parameters, commands, mode requests, stream requests and RC overrides from the GCS.
#include <algorithm>
#include <cmath>
#include <string>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "tools/apmsim/banner.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

void RoverSim::on_param(const mv::Frame& f) {
    if (f.msgid == mv::ParamRequestList::kId) {
        if (!addressed(mv::decode_payload<mv::ParamRequestList>(f.payload_view()).target_system)) {
            return;
        }
        send_banner();
        for (std::size_t i = 0; i < params_.size(); ++i) {
            send_param(i);
        }
        return;
    }
    if (f.msgid == mv::ParamRequestRead::kId) {
        const auto m = mv::decode_payload<mv::ParamRequestRead>(f.payload_view());
        if (!addressed(m.target_system)) {
            return;
        }
        if (rover2_telemetry()) {
            // GCS_Mavlink.pde: an unknown name or index is reported in a text, and the PARAM_VALUE echoes
            // the request's index (-1, that is 65535, for a read by name).
            if (m.param_index != -1) {
                if (m.param_index < 0 || static_cast<std::size_t>(m.param_index) >= params_.size()) {
                    r2_text(1, "Unknown parameter index " + std::to_string(m.param_index));
                    return;
                }
                send_param(static_cast<std::size_t>(m.param_index));
                return;
            }
            const std::string name(mv::text_of(m.param_id).substr(0, 16));
            if (const auto i = params_.index_of(name)) {
                send_param(*i, UINT16_MAX);
            } else {
                r2_text(1, "Unknown parameter " + name);
            }
            return;
        }
        if (m.param_index >= 0) {
            if (static_cast<std::size_t>(m.param_index) < params_.size()) {
                send_param(static_cast<std::size_t>(m.param_index));
            }
        } else if (const auto i = params_.index_of(mv::text_of(m.param_id))) {
            send_param(*i);
        }
        return;  // an unknown parameter gets no answer, as on the board
    }
    const auto m = mv::decode_payload<mv::ParamSet>(f.payload_view());
    if (!addressed(m.target_system)) {
        return;
    }
    const std::string name(mv::text_of(m.param_id));
    if (rover2_telemetry() && !std::isfinite(m.param_value)) {
        return;  // "not nan, not inf"
    }
    if (const auto i = params_.set(name, m.param_value)) {
        unsaved_params_.erase(name);  // set_and_save()
        apply_param_side_effects(name, "param", now_);
        // 2.x answers with index -1: "we don't actually know what its index is".
        send_param(*i, rover2_telemetry() ? std::optional<std::uint16_t>(UINT16_MAX) : std::nullopt);
    }
}

void RoverSim::send_param(std::size_t index, std::optional<std::uint16_t> reported_index) {
    const Param& p = params_.at(index);
    mv::ParamValue v;
    mv::set_text(v.param_id, p.name);
    v.param_value = p.value;
    v.param_type = static_cast<std::uint8_t>(p.type);
    v.param_count = static_cast<std::uint16_t>(params_.size());
    v.param_index = reported_index.value_or(static_cast<std::uint16_t>(index));
    out_.reply(v);
}

void RoverSim::apply_param_side_effects(const std::string& name, const std::string& cause, TimePoint now) {
    if (name.rfind("SR0_", 0) == 0 && phase_ == BootPhase::Ready) {
        load_stream_rates(now);
    }
    if (name == "CRUISE_SPEED" && config_.firmware.auto_speed == FirmwareProfile::AutoSpeed::CruiseSpeed) {
        note_speed(cause, now);  // 2.x: the new value applies at once
    }
    if (name == "WP_SPEED") {
        // AR_WPNav reads WP_SPEED when it is initialised (entering AUTO, GUIDED or RTL): the speed changes
        // now only if none of them was entered since the boot.
        note_speed(cause, now);
    }
}

void RoverSim::load_stream_rates(TimePoint now) {
    for (const auto& g : stream_groups()) {
        streams_.set_group_rate(g.group, params_.get("SR0_" + std::string(g.param_suffix), 0), now);
    }
}

void RoverSim::on_request_data_stream(const mv::Frame& f, TimePoint now) {
    const auto m = mv::decode_payload<mv::RequestDataStream>(f.payload_view());
    if (!addressed(m.target_system) || phase_ != BootPhase::Ready) {
        return;
    }
    const double hz =
        m.start_stop == 0 ? 0.0 : std::min<double>(m.req_message_rate, StreamScheduler::kMaxRateHz);
    // ArduPilot stores the rate in the port's SRn_ parameter, so it outlives a reboot.
    for (const auto& g : stream_groups()) {
        if (m.req_stream_id == 0 || static_cast<std::uint8_t>(g.group) == m.req_stream_id) {
            params_.set("SR0_" + std::string(g.param_suffix), static_cast<float>(hz));
            streams_.set_group_rate(g.group, hz, now);
        }
    }
}

void RoverSim::on_set_mode(const mv::Frame& f, TimePoint now) {
    if (rover2_commands()) {
        r2_on_set_mode(f, now);
        return;
    }
    const auto m = mv::decode_payload<mv::SetMode>(f.payload_view());
    if (!addressed(m.target_system)) {
        return;
    }
    std::uint8_t result = mavlink::kResultFailed;
    const auto mode = mode_from_number(m.custom_mode);
    if (phase_ != BootPhase::Ready) {
        result = mavlink::kResultTemporarilyRejected;
    } else if ((m.base_mode & mavlink::kModeFlagCustomModeEnabled) != 0 && mode &&
               *mode != RoverMode::Initialising) {
        result = set_mode(*mode, "command", now) ? mavlink::kResultAccepted : mavlink::kResultFailed;
    }
    mv::CommandAck ack;  // later firmware acknowledges SET_MODE with the message id as the command
    ack.command = mv::SetMode::kId;
    ack.result = result;
    ack.target_system = f.sysid;
    ack.target_component = f.compid;
    out_.reply(ack);
}

void RoverSim::on_command_long(const mv::Frame& f, TimePoint now) {
    if (rover2_commands()) {
        r2_on_command_long(f, now);
        return;
    }
    on_command(mv::decode_payload<mv::CommandLong>(f.payload_view()), f, now);
}

// The commands both COMMAND_LONG and COMMAND_INT carry (ArduPilot turns one into the other and handles them
// in one place).
void RoverSim::on_command(const mv::CommandLong& c, const mv::Frame& f, TimePoint now) {
    if (!addressed(c.target_system)) {
        return;
    }
    std::uint8_t result = mavlink::kResultUnsupported;
    bool reboot_after_ack = false;
    const bool ready = phase_ == BootPhase::Ready;
    switch (c.command) {
        case mavlink::kCmdDoSetMode: {
            const auto mode = mode_from_number(static_cast<std::uint32_t>(c.param2));
            if (!ready) {
                result = mavlink::kResultTemporarilyRejected;
            } else if ((static_cast<int>(c.param1) & mavlink::kModeFlagCustomModeEnabled) == 0 || !mode ||
                       *mode == RoverMode::Initialising) {
                result = mavlink::kResultFailed;
            } else {
                result = set_mode(*mode, "command", now) ? mavlink::kResultAccepted : mavlink::kResultFailed;
            }
            break;
        }
        case kCmdDoChangeSpeed: {
            // GCS_MAVLINK_Rover::handle_command_int_packet(): param2 is the new speed (m/s), param3
            // (throttle) is not used; a climb or descent speed type (param1 2, 3) is DENIED. The mode sets
            // the speed (Mode::set_desired_speed()): AUTO, GUIDED and RTL take it (AR_WPNav::set_speed_max():
            // at least 0.05 m/s), the others (HOLD, MANUAL...) fail.
            const auto type = std::lround(c.param1);
            const bool takes_speed = is_navigating(mode_);
            if (!config_.firmware.change_speed_command) {
                result = mavlink::kResultUnsupported;
            } else if (type == 2 || type == 3) {
                result = mavlink::kResultDenied;
            } else if (!takes_speed || !(c.param2 >= 0.05F)) {
                result = mavlink::kResultFailed;
            } else {
                speed_override_ = c.param2;
                note_speed("command", now);
                result = mavlink::kResultAccepted;
            }
            break;
        }
        case mavlink::kCmdMissionStart:
            result = !ready                                      ? mavlink::kResultTemporarilyRejected
                     : set_mode(RoverMode::Auto, "command", now) ? mavlink::kResultAccepted
                                                                 : mavlink::kResultFailed;
            break;
        case kCmdNavReturnToLaunch:
            result = !ready                                     ? mavlink::kResultTemporarilyRejected
                     : set_mode(RoverMode::Rtl, "command", now) ? mavlink::kResultAccepted
                                                                : mavlink::kResultFailed;
            break;
        case mavlink::kCmdComponentArmDisarm: {
            // GCS_MAVLINK::handle_command_component_arm_disarm(): param1 1 arms, 0 disarms, anything else is
            // UNSUPPORTED; param2 21196 or 2989 forces (the checks are skipped).
            const auto force = std::lround(c.param2);
            if (!config_.firmware.arming_checks && !ready) {
                result = mavlink::kResultTemporarilyRejected;
            } else if (c.param1 == 1.0F || c.param1 == 0.0F) {
                result = arm_disarm(c.param1 == 1.0F, force == 21196 || force == 2989);
            } else {
                result = mavlink::kResultUnsupported;
            }
            break;
        }
        case mavlink::kCmdDoSetMissionCurrent: {
            const auto seq = static_cast<std::uint16_t>(std::clamp(c.param1, 0.0F, 65535.0F));
            result = seq < store_.count() && set_current(seq, now) ? mavlink::kResultAccepted
                                                                   : mavlink::kResultDenied;
            if (result == mavlink::kResultAccepted) {
                send_mission_current();
            }
            break;
        }
        case mavlink::kCmdPreflightRebootShutdown:
            if (std::lround(c.param1) == 1) {
                result = mavlink::kResultAccepted;
                reboot_after_ack = true;
            } else {
                result = mavlink::kResultUnsupported;
            }
            break;
        case mavlink::kCmdGetHomePosition:
            send_home_position();
            result = mavlink::kResultAccepted;
            break;
        case mavlink::kCmdRequestAutopilotCapabilities:
            send_autopilot_version();
            result = mavlink::kResultAccepted;
            break;
        case kCmdDoSendBanner:
            send_banner();
            result = mavlink::kResultAccepted;
            break;
        case mavlink::kCmdRequestMessage: {
            const auto id = static_cast<std::uint32_t>(std::max(0.0F, c.param1));
            result = mavlink::kResultAccepted;
            if (id == mv::HomePosition::kId) {
                send_home_position();
            } else if (id == mv::AutopilotVersion::kId) {
                send_autopilot_version();
            } else if (ready && (id == mv::SysStatus::kId || id == mv::GpsRawInt::kId ||
                                 id == mv::Attitude::kId || id == mv::GlobalPositionInt::kId ||
                                 id == mv::VfrHud::kId || id == mv::MissionCurrent::kId ||
                                 id == mv::SystemTime::kId || id == mv::BatteryStatus::kId ||
                                 id == mv::NavControllerOutput::kId || id == mv::RcChannels::kId ||
                                 id == mv::RcChannelsRaw::kId || id == mv::ServoOutputRaw::kId)) {
                send_stream_message(id, now);
            } else {
                result = mavlink::kResultDenied;
            }
            break;
        }
        case mavlink::kCmdSetMessageInterval: {
            const auto id = static_cast<std::uint32_t>(std::max(0.0F, c.param1));
            const float us = c.param2;
            if (us < -0.5F) {
                streams_.set_message_interval(id, Duration::zero(), now);  // -1: stop it
            } else if (us < 0.5F) {
                streams_.set_message_interval(id, std::nullopt, now);  // 0: back to the default
            } else {
                const auto interval = std::max<Duration>(
                    std::chrono::duration_cast<Duration>(std::chrono::duration<double, std::micro>(us)),
                    milliseconds(20));  // the same 50 Hz ceiling as the stream groups
                streams_.set_message_interval(id, interval, now);
            }
            result = mavlink::kResultAccepted;
            break;
        }
        default:
            break;
    }
    mv::CommandAck ack;
    ack.command = c.command;
    ack.result = result;
    ack.target_system = f.sysid;
    ack.target_component = f.compid;
    if (reboot_after_ack) {
        out_.send(ack);  // the acknowledgement leaves before the board goes down
        reboot(now);
        return;
    }
    out_.reply(ack);
}

void RoverSim::on_rc_override(const mv::Frame& f, TimePoint now) {
    const auto m = mv::decode_payload<mv::RcChannelsOverride>(f.payload_view());
    if (!addressed(m.target_system)) {
        return;
    }
    if (rover2_commands() && f.sysid != static_cast<std::uint8_t>(params_.get("SYSID_MYGCS", 255))) {
        return;  // "Only accept control from our gcs"
    }
    const std::array<std::uint16_t, 8> ch{m.chan1_raw, m.chan2_raw, m.chan3_raw, m.chan4_raw,
                                          m.chan5_raw, m.chan6_raw, m.chan7_raw, m.chan8_raw};
    for (std::size_t i = 0; i < ch.size(); ++i) {
        if (ch[i] != UINT16_MAX) {  // UINT16_MAX: leave this channel as it is
            rc_override_[i] = ch[i];
        }
    }
    rc_override_at_ = now;
}

std::uint16_t RoverSim::rc_input(int channel, TimePoint now) const {
    const auto i = static_cast<std::size_t>(channel - 1);
    const auto timeout = std::chrono::duration_cast<Duration>(
        std::chrono::duration<double>(std::max(0.0F, params_.get("RC_OVERRIDE_TIME", 3))));
    if (i < rc_override_.size() && rc_override_[i] != 0 && now - rc_override_at_ <= timeout) {
        return rc_override_[i];
    }
    return static_cast<std::uint16_t>(params_.get("RC" + std::to_string(channel) + "_TRIM", 1500));
}

}  // namespace airseg::apmsim
