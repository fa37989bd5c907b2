#include "services/autopilot/ardupilot/mission_codec.hpp"

#include <cmath>

#include "services/autopilot/mavlink/enums.hpp"

namespace airseg::autopilot::ardupilot {

namespace {
std::int32_t to_e7(double degrees) {
    return static_cast<std::int32_t>(std::llround(degrees * 1e7));
}
}  // namespace

mavlink::MissionItemInt encode_item(const MissionItem& item, bool stop_as_jump) {
    mavlink::MissionItemInt m;
    m.autocontinue = 1;
    if (item.kind == MissionItem::Kind::Stop && stop_as_jump) {
        m.command = mavlink::kCmdDoJump;
        m.frame = mavlink::kFrameMission;
        m.param1 = static_cast<float>(kJumpPastTheEnd);
        m.param2 = -1.0f;
        return m;
    }
    switch (item.kind) {
        case MissionItem::Kind::Waypoint:
        case MissionItem::Kind::Stop:
            m.command = item.kind == MissionItem::Kind::Waypoint ? mavlink::kCmdNavWaypoint
                                                                 : mavlink::kCmdNavLoiterUnlim;
            m.frame = mavlink::kFrameGlobalRelativeAltInt;
            m.x = to_e7(item.lat);
            m.y = to_e7(item.lon);
            m.z = static_cast<float>(item.alt);
            if (item.kind == MissionItem::Kind::Waypoint) {
                m.param1 = static_cast<float>(item.hold_s.value_or(0.0));
                m.param2 = static_cast<float>(item.radius.value_or(0.0));
            }
            break;
        case MissionItem::Kind::JumpTo:
            m.command = mavlink::kCmdDoJump;
            m.frame = mavlink::kFrameMission;
            m.param1 = static_cast<float>(item.jump_slot);
            m.param2 = -1.0f;
            break;
    }
    return m;
}

MissionItem decode_item(const mavlink::MissionItemInt& m) {
    MissionItem item;
    if (m.command == mavlink::kCmdDoJump) {
        if (std::lround(m.param1) == kJumpPastTheEnd) {
            item.kind = MissionItem::Kind::Stop;  // a Stop as a board without NAV_LOITER_UNLIM holds it
            return item;
        }
        item.kind = MissionItem::Kind::JumpTo;
        item.jump_slot = static_cast<std::uint16_t>(std::lround(m.param1));
        return item;
    }
    item.kind =
        m.command == mavlink::kCmdNavLoiterUnlim ? MissionItem::Kind::Stop : MissionItem::Kind::Waypoint;
    item.lat = static_cast<double>(m.x) * 1e-7;
    item.lon = static_cast<double>(m.y) * 1e-7;
    item.alt = m.z;
    if (m.command == mavlink::kCmdNavWaypoint) {
        if (m.param1 > 0) {
            item.hold_s = m.param1;
        }
        if (m.param2 > 0) {
            item.radius = m.param2;
        }
    }
    return item;
}

mavlink::MissionItemInt home_item(const Position& home) {
    mavlink::MissionItemInt m;
    m.command = mavlink::kCmdNavWaypoint;
    m.frame = mavlink::kFrameGlobal;
    m.autocontinue = 1;
    m.x = to_e7(home.lat);
    m.y = to_e7(home.lon);
    m.z = static_cast<float>(home.alt);
    return m;
}

}  // namespace airseg::autopilot::ardupilot
