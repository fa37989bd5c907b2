#include "tools/apmsim/legacy_mission_server.hpp"

#include <algorithm>
#include <cmath>

#include "services/autopilot/mavlink/enums.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

namespace {

// The 2.x firmware's system id; it answers only mission messages addressed to it (no broadcast 0).
constexpr std::uint8_t kRover2System = 1;
// The 2.x severities (GCS_MAVLink.h: SEVERITY_LOW = 1).
constexpr std::uint8_t kSeverityLow = 1;

// C's float to integer conversion truncates; out-of-range and non-finite values are undefined there, so the
// simulator saturates them.
std::int32_t to_i32(float v) {
    if (!std::isfinite(v)) {
        return 0;
    }
    return static_cast<std::int32_t>(std::clamp<double>(std::trunc(v), -2147483648.0, 2147483647.0));
}

// param1 goes into the one-byte p1 field.
std::uint8_t to_p1(float v) {
    return static_cast<std::uint8_t>(static_cast<std::uint32_t>(to_i32(v)) & 0xFFU);
}

bool for_rover2(std::uint8_t target_system) {
    return target_system == kRover2System;
}

}  // namespace

StoredItem rover2_blank() {
    StoredItem s;
    s.command = 0;  // CMD_BLANK
    s.frame = mavlink::kFrameGlobal;
    s.autocontinue = 1;
    return s;
}

Rover2Stored rover2_store(const mv::MissionItem& m) {
    Rover2Stored r;
    StoredItem& s = r.item;
    s = rover2_blank();
    s.command = m.command;
    switch (m.frame) {
        // The frames the 2.x firmware accepts. Its MAV_FRAME_LOCAL_NED case is inside "#ifdef
        // MAV_FRAME_LOCAL_NED", and the MAVLink 1.0 headers define frames as enum values, not macros, so that
        // case is not compiled.
        case mavlink::kFrameMission:
        case mavlink::kFrameGlobal:
        case mavlink::kFrameGlobalRelativeAlt:
            // GCS_Mavlink.pde: tell_command.lat = 1.0e7f * packet.x (single precision, truncated).
            s.lat_e7 = to_i32(1.0e7F * m.x);
            s.lon_e7 = to_i32(1.0e7F * m.y);
            s.alt = static_cast<float>(to_i32(m.z * 1.0e2F));  // centimetres
            s.frame = m.frame == mavlink::kFrameGlobalRelativeAlt ? mavlink::kFrameGlobalRelativeAlt
                                                                  : mavlink::kFrameGlobal;
            break;
        default:
            r.result = mavlink::kMissionUnsupportedFrame;
            return r;
    }
    switch (m.command) {
        case kCmdNavWaypoint:
        case kCmdNavReturnToLaunch:
            break;
        case kCmdNavTakeoff:
        case mavlink::kCmdDoSetHome:
            s.param1 = to_p1(m.param1);
            break;
        case kCmdConditionChangeAlt:
        case kCmdConditionDelay:
        case kCmdConditionDistance:
            s.lat_e7 = to_i32(m.param1);
            break;
        case kCmdDoJump:
            s.lat_e7 = to_i32(m.param2);  // repeats
            s.param1 = to_p1(m.param1);   // target item
            break;
        case mavlink::kCmdDoRepeatServo:
            s.lon_e7 = to_i32(m.param4);
            [[fallthrough]];
        case mavlink::kCmdDoRepeatRelay:
        case kCmdDoChangeSpeed:
            s.lat_e7 = to_i32(m.param3);
            s.alt = static_cast<float>(to_i32(m.param2));
            s.param1 = to_p1(m.param1);
            break;
        case mavlink::kCmdDoSetParameter:
        case mavlink::kCmdDoSetRelay:
        case mavlink::kCmdDoSetServo:
            s.alt = static_cast<float>(to_i32(m.param2));
            s.param1 = to_p1(m.param1);
            break;
        default:
            r.result = mavlink::kMissionUnsupported;
            return r;
    }
    r.result = mavlink::kMissionAccepted;
    return r;
}

mv::MissionItem rover2_download(const StoredItem& s, std::int32_t home_alt_cm) {
    mv::MissionItem m;
    m.frame = s.frame;
    m.command = s.command;
    m.autocontinue = 1;
    const bool place = s.command < kCmdNavLast || s.command == kCmdConditionChangeAlt;
    if (place) {
        // get_cmd_with_index() adds the home altitude to a relative one before the download scales it.
        const double alt_cm = s.alt + (s.frame == mavlink::kFrameGlobalRelativeAlt ? home_alt_cm : 0);
        m.x = static_cast<float>(s.lat_e7 / 1.0e7);
        m.y = static_cast<float>(s.lon_e7 / 1.0e7);
        m.z = static_cast<float>(alt_cm / 1.0e2);
    }
    switch (s.command) {
        case kCmdNavTakeoff:
        case mavlink::kCmdDoSetHome:
            m.param1 = s.param1;
            break;
        case kCmdConditionChangeAlt:
            m.x = 0;
            m.y = 0;
            [[fallthrough]];
        case kCmdConditionDelay:
        case kCmdConditionDistance:
            m.param1 = static_cast<float>(s.lat_e7);
            break;
        case kCmdDoJump:
            m.param2 = static_cast<float>(s.lat_e7);
            m.param1 = s.param1;
            break;
        case mavlink::kCmdDoRepeatServo:
            m.param4 = static_cast<float>(s.lon_e7);
            [[fallthrough]];
        case mavlink::kCmdDoRepeatRelay:
        case kCmdDoChangeSpeed:
            m.param3 = static_cast<float>(s.lat_e7);
            m.param2 = s.alt;
            m.param1 = s.param1;
            break;
        case mavlink::kCmdDoSetParameter:
        case mavlink::kCmdDoSetRelay:
        case mavlink::kCmdDoSetServo:
            m.param2 = s.alt;
            m.param1 = s.param1;
            break;
        default:
            break;
    }
    return m;
}

bool LegacyMissionServer::handle(const mv::Frame& f, TimePoint now) {
    switch (f.msgid) {
        case mv::MissionRequestList::kId: {
            if (!for_rover2(mv::decode_payload<mv::MissionRequestList>(f.payload_view()).target_system)) {
                return true;
            }
            mv::MissionCount c;
            c.target_system = f.sysid;
            c.target_component = f.compid;
            c.count = static_cast<std::uint16_t>(store_.count());
            out_.reply(c);
            if (receiving_) {
                ++stats_.uploads_cancelled;  // "record that we are sending commands (i.e. not receiving)"
            }
            receiving_ = false;
            dest_sysid_ = f.sysid;
            dest_compid_ = f.compid;
            return true;
        }
        case mv::MissionRequest::kId: {
            const auto r = mv::decode_payload<mv::MissionRequest>(f.payload_view());
            if (!for_rover2(r.target_system)) {
                return true;
            }
            const StoredItem s = r.seq < store_.count() ? store_.at(r.seq) : rover2_blank();
            mv::MissionItem m = rover2_download(s, hooks_.home_alt_cm());
            m.target_system = f.sysid;
            m.target_component = f.compid;
            m.seq = r.seq;
            m.current = r.seq == hooks_.command_index() ? 1 : 0;
            ++stats_.items_sent;
            out_.reply(m);
            return true;
        }
        case mv::MissionAck::kId:
            return true;  // not used by the board
        case mv::MissionClearAll::kId: {
            if (!for_rover2(mv::decode_payload<mv::MissionClearAll>(f.payload_view()).target_system)) {
                return true;
            }
            store_.truncate(1);  // CMD_TOTAL = 0
            ack(f, mavlink::kMissionAccepted);
            hooks_.changed();
            return true;
        }
        case mv::MissionSetCurrent::kId: {
            const auto m = mv::decode_payload<mv::MissionSetCurrent>(f.payload_view());
            if (!for_rover2(m.target_system)) {
                return true;
            }
            hooks_.change_command(m.seq);
            mv::MissionCurrent c;
            c.seq = hooks_.command_index();
            out_.reply(c);
            return true;
        }
        case mv::MissionCount::kId: {
            const auto m = mv::decode_payload<mv::MissionCount>(f.payload_view());
            if (!for_rover2(m.target_system)) {
                return true;
            }
            if (m.count == 0) {
                // Not from the source: 2.x computes CMD_TOTAL = count - 1 and underflows. The MAVLink
                // specification's answer: the mission is cleared (home stays) and ACCEPTED.
                receiving_ = false;
                store_.truncate(1);
                ++stats_.uploads_completed;
                ack(f, mavlink::kMissionAccepted);
                hooks_.changed();
                return true;
            }
            const std::size_t count = std::min<std::size_t>(m.count, store_.capacity());
            store_.resize(count, rover2_blank());
            hooks_.changed();
            receiving_ = true;
            request_i_ = 0;
            request_last_ = static_cast<std::uint16_t>(count - 1);
            last_heard_ = now;
            request(now);
            return true;
        }
        case mv::MissionWritePartialList::kId: {
            const auto m = mv::decode_payload<mv::MissionWritePartialList>(f.payload_view());
            if (!for_rover2(m.target_system)) {
                return true;
            }
            const auto total = static_cast<std::int32_t>(store_.count()) - 1;
            if (m.start_index < 0 || m.start_index > total || m.end_index > total ||
                m.end_index < m.start_index) {
                text("flight plan update rejected");
                return true;
            }
            receiving_ = true;
            request_i_ = static_cast<std::uint16_t>(m.start_index);
            request_last_ = static_cast<std::uint16_t>(m.end_index);
            last_heard_ = now;
            request(now);
            return true;
        }
        case mv::MissionItem::kId: {
            const auto m = mv::decode_payload<mv::MissionItem>(f.payload_view());
            if (for_rover2(m.target_system)) {
                on_item(f, m, now);
            }
            return true;
        }
        default:
            return false;
    }
}

void LegacyMissionServer::on_item(const mv::Frame& f, const mv::MissionItem& m, TimePoint now) {
    const Rover2Stored stored = rover2_store(m);
    if (stored.result != mavlink::kMissionAccepted) {
        ack(f, stored.result);  // the transfer goes on: the same item is asked for again
        return;
    }
    if (m.current == 2) {
        hooks_.guided_goto(stored.item);
        ack(f, mavlink::kMissionAccepted);
        return;
    }
    if (!receiving_) {
        ack(f, mavlink::kMissionError);
        return;
    }
    if (m.seq != request_i_) {
        ack(f, mavlink::kMissionInvalidSequence);
        return;
    }
    StoredItem item = stored.item;
    if (m.seq == 0) {
        item.frame = mavlink::kFrameGlobal;  // set_cmd_with_index() keeps home's altitude absolute
    }
    store_.write(m.seq, item);
    ++stats_.items_received;
    last_heard_ = now;
    ++request_i_;
    if (request_i_ > request_last_) {
        receiving_ = false;
        ++stats_.uploads_completed;
        ack(f, mavlink::kMissionAccepted);
        text("flight plan received");
        hooks_.changed();
        return;
    }
    request(now);
}

void LegacyMissionServer::request(TimePoint now) {
    mv::MissionRequest r;
    r.target_system = dest_sysid_;
    r.target_component = dest_compid_;
    r.seq = request_i_;
    last_request_ = now;
    out_.reply(r);
}

void LegacyMissionServer::handle_timeout(TimePoint now) {
    if (!receiving_) {
        return;
    }
    if (now - last_heard_ >= give_up_) {
        receiving_ = false;  // silently: no MISSION_ACK, no text
        ++stats_.uploads_cancelled;
        return;
    }
    if (now - last_request_ >= rerequest_) {
        ++stats_.rerequests;
        request(now);
    }
}

TimePoint LegacyMissionServer::poll_timeout() const {
    if (!receiving_) {
        return kNever;
    }
    return std::min(last_request_ + rerequest_, last_heard_ + give_up_);
}

void LegacyMissionServer::ack(const mv::Frame& to, std::uint8_t result) {
    mv::MissionAck a;
    a.target_system = to.sysid;
    a.target_component = to.compid;
    a.type = result;
    out_.reply(a);
}

void LegacyMissionServer::text(std::string_view message) {
    mv::Statustext t;
    t.severity = kSeverityLow;
    mv::set_text(t.text, message);
    out_.reply(t);
}

}  // namespace airseg::apmsim
