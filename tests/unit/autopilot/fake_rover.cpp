#include "tests/unit/autopilot/fake_rover.hpp"

#include <algorithm>
#include <cmath>

namespace airseg::autopilot::testing {

namespace {
constexpr std::uint8_t kGcsMavStateCalibrating = 2;
constexpr std::uint8_t kMavStateStandby = 3;
constexpr Duration kRerequest = seconds(1);
constexpr Duration kUploadAbort = seconds(8);
}  // namespace

FakeRover::FakeRover(Options options, TimePoint now)
    : options_(options),
      encoder_(1, 1, options.version),
      boot_start_(now - options.boot_delay - options.calibration),
      boot_done_(now),
      next_heartbeat_(now),
      boot_texts_sent_(true) {
    for (std::size_t i = 0; i < options_.params; ++i) {
        const std::string name = "PARAM_" + std::to_string(i);
        params_[name] = static_cast<float>(i);
        param_order_.push_back(name);
    }
    params_["CRUISE_SPEED"] = 2.0f;
    param_order_.push_back("CRUISE_SPEED");
    params_["WP_RADIUS"] = 2.0f;
    param_order_.push_back("WP_RADIUS");
    if (options_.current_rover_speed) {
        params_["WP_SPEED"] = 2.0f;
        param_order_.push_back("WP_SPEED");
    }
    mav::MissionItemInt home;
    home.frame = 0;
    home.command = 16;
    home.x = 413900000;
    home.y = 21100000;
    mission_.push_back(home);
}

void FakeRover::reboot(TimePoint now) {
    boot_start_ = now;
    boot_done_ = now + options_.boot_delay + options_.calibration;
    next_heartbeat_ = now + options_.boot_delay;
    boot_texts_sent_ = false;
    receiving_ = false;
    mode_ = kHold;
    armed_ = false;
    current_ = 0;
    last_override_.reset();
    out_.clear();
    out_.push_back({0x00, 0xFE, 0x13, 0x37, 0xFD, 0x02});  // bootloader noise
}

void FakeRover::parameter_list_asked(TimePoint) {
    if (options_.banner_on_param_list) {
        text(6, "ArduRover V4.6.2 (fake0001)");
        text(6, "ChibiOS: 6a85082c");
        text(6, "fakeboard 00000001 00000002 00000003");
    }
    for (std::size_t i = 0; i < param_order_.size(); ++i) {
        send_param(i);
    }
}

std::uint32_t FakeRover::time_boot_ms(TimePoint now) const {
    return static_cast<std::uint32_t>(std::chrono::duration_cast<milliseconds>(now - boot_start_).count());
}

void FakeRover::text(std::uint8_t severity, const std::string& s) {
    mav::Statustext t;
    t.severity = severity;
    mav::set_text(t.text, s);
    send(t);
}

void FakeRover::send_heartbeat(TimePoint now) {
    mav::Heartbeat hb;
    hb.type = 10;
    hb.autopilot = 3;
    hb.base_mode = 1;
    if ((armed_ || !options_.arming_required) && now >= boot_done_) {
        hb.base_mode |= 128;  // MAV_MODE_FLAG_SAFETY_ARMED
    }
    hb.custom_mode = now < initialising_until_ ? 16u : mode_;  // 16: Rover's INITIALISING
    hb.system_status = now < boot_done_ ? kGcsMavStateCalibrating : kMavStateStandby;
    if (options_.uninit_in_hold && mode_ == kHold && now >= boot_done_) {
        hb.system_status = 0;  // APM:Rover 2.x's HOLD
    }
    send(hb);
    mav::SystemTime st;
    st.time_boot_ms = time_boot_ms(now);
    send(st);
    mav::GlobalPositionInt gp;
    gp.time_boot_ms = st.time_boot_ms;
    gp.lat = 413900000 + static_cast<std::int32_t>(st.time_boot_ms / 100);
    gp.lon = 21100000;
    gp.alt = 12000;
    gp.hdg = 9000;
    send(gp);
    mav::MissionCurrent mc;
    mc.seq = current_;
    mc.total = static_cast<std::uint16_t>(mission_.size());
    send(mc);
}

void FakeRover::handle_timeout(TimePoint now) {
    if (now < stall_until_) {
        return;
    }
    if (now >= boot_start_ + options_.boot_delay && !boot_texts_sent_) {
        boot_texts_sent_ = true;
        if (options_.boot_texts) {
            text(6, "Initialising APM");
            text(6, "APM:Rover V2.51 (fake)");
        }
    }
    if (now >= next_heartbeat_) {
        send_heartbeat(now);
        next_heartbeat_ = now + seconds(1);
    }
    if (receiving_) {
        if (now - last_receive_ >= kUploadAbort) {
            receiving_ = false;
            ++upload_aborts_;
            text(4, "Mission upload timeout");
        } else if (now - last_request_ >= kRerequest) {
            request_item(now);
        }
    }
}

TimePoint FakeRover::poll_timeout() const {
    TimePoint t = std::max(next_heartbeat_, stall_until_);
    if (!boot_texts_sent_) {
        t = std::min(t, boot_start_ + options_.boot_delay);
    }
    if (receiving_) {
        t = std::min({t, last_request_ + kRerequest, last_receive_ + kUploadAbort});
    }
    return std::max(t, stall_until_);
}

std::optional<std::vector<std::uint8_t>> FakeRover::poll_transmit() {
    if (out_.empty()) {
        return std::nullopt;
    }
    auto f = std::move(out_.front());
    out_.pop_front();
    return f;
}

void FakeRover::handle_bytes(std::span<const std::uint8_t> bytes, TimePoint now) {
    if (now < stall_until_ || now < boot_start_ + options_.boot_delay) {
        return;
    }
    parser_.push(bytes, [&](const mav::Frame& f) { on_frame(f, now); });
}

void FakeRover::pilot_sets_mode(std::uint32_t mode, TimePoint now) {
    mode_ = mode;
    send_heartbeat(now);
}

void FakeRover::reach(std::uint16_t seq, TimePoint) {
    if (options_.send_item_reached) {
        mav::MissionItemReached r;
        r.seq = seq;
        send(r);
    }
    text(6, "Reached waypoint #" + std::to_string(seq) + " dist 1m");
    if (seq + 1u < mission_.size()) {
        current_ = static_cast<std::uint16_t>(seq + 1);
    }
}

void FakeRover::send_param(std::size_t index) {
    const std::string& name = param_order_[index];
    mav::ParamValue v;
    mav::set_text(v.param_id, name);
    v.param_value = params_[name];
    v.param_type = 9;  // MAV_PARAM_TYPE_REAL32
    v.param_count = static_cast<std::uint16_t>(param_order_.size());
    v.param_index = static_cast<std::uint16_t>(index);
    send(v);
}

void FakeRover::request_item(TimePoint now) {
    last_request_ = now;
    if (options_.request_int) {
        mav::MissionRequestInt r;
        r.target_system = 255;
        r.target_component = requester_compid_;
        r.seq = request_i_;
        send(r);
    } else {
        mav::MissionRequest r;
        r.target_system = 255;
        r.target_component = requester_compid_;
        r.seq = request_i_;
        send(r);
    }
}

void FakeRover::send_ack(std::uint8_t type) {
    mav::MissionAck a;
    a.target_system = 255;
    a.target_component = requester_compid_;
    a.type = type;
    send(a);
}

void FakeRover::set_mode(std::uint32_t mode, TimePoint now) {
    const bool entering_auto = mode == kAuto && mode_ != kAuto;
    mode_ = mode;
    if (entering_auto && options_.restart_mission_on_auto && mission_.size() > 1) {
        current_ = 1;
        mav::MissionCurrent mc;
        mc.seq = current_;
        mc.total = static_cast<std::uint16_t>(mission_.size());
        send(mc);
    }
    send_heartbeat(now);
}

void FakeRover::on_frame(const mav::Frame& f, TimePoint now) {
    requester_compid_ = f.compid;  // answers go to the requester's component, as ArduPilot's do
    switch (f.msgid) {
        case mav::MissionCount::kId: {
            const auto m = mav::decode_payload<mav::MissionCount>(f.payload_view());
            if (m.count > options_.max_items) {
                send_ack(4);
                return;
            }
            if (m.count == 0) {
                mission_.resize(1);
                send_ack(0);
                return;
            }
            receiving_ = true;
            incoming_ = mission_;
            incoming_.resize(m.count);
            request_i_ = 0;
            request_last_ = static_cast<std::uint16_t>(m.count - 1);
            last_receive_ = now;
            request_item(now);
            return;
        }
        case mav::MissionWritePartialList::kId: {
            const auto m = mav::decode_payload<mav::MissionWritePartialList>(f.payload_view());
            if (m.start_index < 0 || m.end_index < m.start_index ||
                static_cast<std::size_t>(m.end_index) >= mission_.size()) {
                send_ack(1);
                return;
            }
            receiving_ = true;
            incoming_ = mission_;
            request_i_ = static_cast<std::uint16_t>(m.start_index);
            request_last_ = static_cast<std::uint16_t>(m.end_index);
            last_receive_ = now;
            request_item(now);
            return;
        }
        case mav::MissionItemInt::kId:
        case mav::MissionItem::kId: {
            mav::MissionItemInt item;
            if (f.msgid == mav::MissionItemInt::kId) {
                item = mav::decode_payload<mav::MissionItemInt>(f.payload_view());
            } else {
                const auto fi = mav::decode_payload<mav::MissionItem>(f.payload_view());
                item.seq = fi.seq;
                item.frame = fi.frame;
                item.command = fi.command;
                item.param1 = fi.param1;
                item.param2 = fi.param2;
                item.param3 = fi.param3;
                item.param4 = fi.param4;
                item.x = static_cast<std::int32_t>(std::lround(static_cast<double>(fi.x) * 1e7));
                item.y = static_cast<std::int32_t>(std::lround(static_cast<double>(fi.y) * 1e7));
                item.z = fi.z;
                item.autocontinue = fi.autocontinue;
            }
            if (!receiving_) {
                send_ack(1);  // MAV_MISSION_ERROR: not receiving
                return;
            }
            if (item.command == 17 && !options_.loiter_unlim) {
                receiving_ = false;
                send_ack(3);  // MAV_MISSION_UNSUPPORTED
                return;
            }
            if (item.command == 16 || item.command == 17) {
                item_frames_.emplace_back(f.msgid, item.frame);
                if (!options_.accepted_frames.empty() && !options_.accepted_frames.contains(item.frame)) {
                    receiving_ = false;
                    send_ack(2);  // MAV_MISSION_UNSUPPORTED_FRAME: the transfer ends
                    return;
                }
            }
            if (item.seq != request_i_) {
                send_ack(13);
                return;
            }
            item.target_system = 0;
            item.target_component = 0;
            incoming_[item.seq] = item;
            last_receive_ = now;
            if (request_i_ == request_last_) {
                receiving_ = false;
                mission_ = incoming_;
                send_ack(0);
                return;
            }
            ++request_i_;
            request_item(now);
            return;
        }
        case mav::MissionRequestList::kId: {
            mav::MissionCount c;
            c.target_system = 255;
            c.target_component = requester_compid_;
            c.count = static_cast<std::uint16_t>(mission_.size());
            send(c);
            return;
        }
        case mav::MissionRequestInt::kId:
        case mav::MissionRequest::kId: {
            const auto seq = mav::decode_payload<mav::MissionRequest>(f.payload_view()).seq;
            if (seq >= mission_.size()) {
                send_ack(13);
                return;
            }
            mav::MissionItemInt item = mission_[seq];
            item.target_system = 255;
            item.target_component = requester_compid_;
            item.seq = seq;
            if (f.msgid == mav::MissionRequestInt::kId) {
                send(item);
            } else {
                mav::MissionItem fi;
                fi.target_system = 255;
                fi.target_component = requester_compid_;
                fi.seq = seq;
                fi.frame = item.frame;
                fi.command = item.command;
                fi.param1 = item.param1;
                fi.param2 = item.param2;
                fi.param3 = item.param3;
                fi.param4 = item.param4;
                fi.x = static_cast<float>(item.x * 1e-7);
                fi.y = static_cast<float>(item.y * 1e-7);
                fi.z = item.z;
                fi.autocontinue = item.autocontinue;
                send(fi);
            }
            return;
        }
        case mav::MissionSetCurrent::kId: {
            const auto m = mav::decode_payload<mav::MissionSetCurrent>(f.payload_view());
            if (m.seq < mission_.size()) {
                current_ = m.seq;
            }
            mav::MissionCurrent mc;
            mc.seq = current_;
            mc.total = static_cast<std::uint16_t>(mission_.size());
            send(mc);
            return;
        }
        case mav::MissionClearAll::kId:
            mission_.resize(1);
            current_ = 0;
            send_ack(0);
            return;
        case mav::ParamRequestList::kId:
            parameter_list_asked(now);
            return;
        case mav::ParamRequestRead::kId: {
            const auto m = mav::decode_payload<mav::ParamRequestRead>(f.payload_view());
            if (m.param_index >= 0 && static_cast<std::size_t>(m.param_index) < param_order_.size()) {
                send_param(static_cast<std::size_t>(m.param_index));
                return;
            }
            const std::string name(mav::text_of(m.param_id));
            const auto it = std::find(param_order_.begin(), param_order_.end(), name);
            if (it != param_order_.end()) {
                send_param(static_cast<std::size_t>(it - param_order_.begin()));
            }
            return;
        }
        case mav::ParamSet::kId: {
            const auto m = mav::decode_payload<mav::ParamSet>(f.payload_view());
            const std::string name(mav::text_of(m.param_id));
            const auto it = std::find(param_order_.begin(), param_order_.end(), name);
            if (it != param_order_.end()) {
                ++param_sets_;
                params_[name] = m.param_value;
                send_param(static_cast<std::size_t>(it - param_order_.begin()));
            }
            return;
        }
        case mav::SetMode::kId: {
            const auto m = mav::decode_payload<mav::SetMode>(f.payload_view());
            if (!refused_modes_.contains(m.custom_mode)) {
                set_mode(m.custom_mode, now);
            }
            return;
        }
        case mav::CommandLong::kId: {
            const auto m = mav::decode_payload<mav::CommandLong>(f.payload_view());
            mav::CommandAck ack;
            ack.command = m.command;
            ack.target_system = 255;
            ack.target_component = requester_compid_;
            if (m.command == 176) {  // MAV_CMD_DO_SET_MODE
                const auto mode = static_cast<std::uint32_t>(m.param2);
                ack.result = refused_modes_.contains(mode) ? 4 : 0;
                send(ack);
                if (ack.result == 0) {
                    set_mode(mode, now);
                }
            } else if (m.command == 178) {  // MAV_CMD_DO_CHANGE_SPEED
                ack.result = !options_.change_speed_command                   ? 3
                             : options_.current_rover_speed && mode_ != kAuto ? 4
                                                                              : 0;
                if (ack.result == 0) {
                    speed_commands_.push_back(m.param2);
                }
                send(ack);
            } else if (m.command == 400 && m.param1 == 1.0F) {  // MAV_CMD_COMPONENT_ARM_DISARM: arm
                ++arm_commands_;
                if (!options_.arm_acks) {
                    return;
                }
                ack.result = options_.arm_refusal.empty() ? 0 : 4;
                send(ack);  // ArduPilot's texts leave through a queue: the refusal's reason after the ack
                if (ack.result == 0) {
                    armed_ = true;
                } else {
                    text(2, "Arm: " + options_.arm_refusal);
                }
            } else {
                ack.result = 0;
                send(ack);
            }
            return;
        }
        case mav::RcChannelsOverride::kId:
            last_override_ = mav::decode_payload<mav::RcChannelsOverride>(f.payload_view());
            last_override_at_ = now;
            ++overrides_;
            return;
        default:
            return;
    }
}

}  // namespace airseg::autopilot::testing
