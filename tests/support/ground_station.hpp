#pragma once
// What a standard ground station (system 254) says to the simulated board through airsegd, and how the
// answers are recognised, for the end-to-end tests of both ways in: the board's network endpoint and the
// radio link. Needs airseg_mavlink.
#include <cstdint>
#include <string_view>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::test {

struct GroundStation {
    mavlink::Encoder encoder{254, 190};

    std::vector<std::uint8_t> heartbeat() {
        mavlink::Heartbeat hb;
        hb.type = 6;  // MAV_TYPE_GCS
        return encoder.encode(hb);
    }
    /// PARAM_REQUEST_LIST: the whole table (current ArduPilot sends its banner first).
    std::vector<std::uint8_t> list_params() {
        mavlink::ParamRequestList list;
        list.target_system = 1;
        list.target_component = 1;
        return encoder.encode(list);
    }
    std::vector<std::uint8_t> read_param(std::string_view name) {
        mavlink::ParamRequestRead read;
        read.target_system = 1;
        read.target_component = 1;
        read.param_index = -1;
        mavlink::set_text(read.param_id, name);
        return encoder.encode(read);
    }
    /// A mission item, the answer to the vehicle's request for `seq`.
    std::vector<std::uint8_t> mission_item(std::uint16_t seq, double lat, double lon,
                                           std::uint16_t command = mavlink::kCmdNavWaypoint) {
        mavlink::MissionItemInt item;
        item.target_system = 1;
        item.target_component = 1;
        item.seq = seq;
        item.frame = mavlink::kFrameGlobalRelativeAltInt;
        item.command = command;
        item.autocontinue = 1;
        item.x = static_cast<std::int32_t>(lat * 1e7);
        item.y = static_cast<std::int32_t>(lon * 1e7);
        return encoder.encode(item);
    }
    /// MISSION_CLEAR_ALL for the vehicle's mission.
    std::vector<std::uint8_t> mission_clear() {
        mavlink::MissionClearAll clear;
        clear.target_system = 1;
        clear.target_component = 1;
        return encoder.encode(clear);
    }
    /// The start of a mission upload of `items` items.
    std::vector<std::uint8_t> mission_upload(std::uint16_t items) {
        mavlink::MissionCount count;
        count.target_system = 1;
        count.target_component = 1;
        count.count = items;
        return encoder.encode(count);
    }

    static bool board_heartbeat(const mavlink::Frame& f) {
        return f.msgid == mavlink::Heartbeat::kId && f.sysid == 1;
    }
    static bool param_value(const mavlink::Frame& f, std::string_view name) {
        return f.msgid == mavlink::ParamValue::kId &&
               mavlink::text_of(mavlink::decode_payload<mavlink::ParamValue>(f.payload_view()).param_id) ==
                   name;
    }
    /// The item a MISSION_REQUEST_INT or MISSION_REQUEST addressed to this station asks for, or -1.
    static int mission_request(const mavlink::Frame& f) {
        if (f.msgid == mavlink::MissionRequestInt::kId) {
            const auto r = mavlink::decode_payload<mavlink::MissionRequestInt>(f.payload_view());
            return r.target_system == 254 ? r.seq : -1;
        }
        if (f.msgid == mavlink::MissionRequest::kId) {
            const auto r = mavlink::decode_payload<mavlink::MissionRequest>(f.payload_view());
            return r.target_system == 254 ? r.seq : -1;
        }
        return -1;
    }
    /// MISSION_ACK MAV_MISSION_DENIED addressed to this station.
    static bool mission_denied(const mavlink::Frame& f) {
        if (f.msgid != mavlink::MissionAck::kId) {
            return false;
        }
        const auto ack = mavlink::decode_payload<mavlink::MissionAck>(f.payload_view());
        return ack.target_system == 254 && ack.type == mavlink::kMissionDenied;
    }
};

}  // namespace airseg::test
