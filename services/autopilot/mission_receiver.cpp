#include "services/autopilot/mission_receiver.hpp"

#include <array>
#include <utility>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::autopilot {

namespace mav = airseg::mavlink;

namespace {

constexpr std::size_t kTextLength = 50;  // STATUSTEXT's text field

std::string command_name(std::uint16_t command) {
    static constexpr std::array<std::pair<std::uint16_t, const char*>, 12> kNames{{
        {mav::kCmdNavWaypoint, "MAV_CMD_NAV_WAYPOINT"},
        {mav::kCmdNavLoiterUnlim, "MAV_CMD_NAV_LOITER_UNLIM"},
        {18, "MAV_CMD_NAV_LOITER_TURNS"},
        {mav::kCmdNavLoiterTime, "MAV_CMD_NAV_LOITER_TIME"},
        {20, "MAV_CMD_NAV_RETURN_TO_LAUNCH"},
        {21, "MAV_CMD_NAV_LAND"},
        {22, "MAV_CMD_NAV_TAKEOFF"},
        {mav::kCmdDoJump, "MAV_CMD_DO_JUMP"},
        {mav::kCmdDoSetHome, "MAV_CMD_DO_SET_HOME"},
        {mav::kCmdDoSetRelay, "MAV_CMD_DO_SET_RELAY"},
        {mav::kCmdDoSetServo, "MAV_CMD_DO_SET_SERVO"},
        {mav::kCmdDoRepeatServo, "MAV_CMD_DO_REPEAT_SERVO"},
    }};
    for (const auto& [id, name] : kNames) {
        if (id == command) {
            return std::string(name) + " (" + std::to_string(command) + ")";
        }
    }
    return "MAV_CMD " + std::to_string(command);
}

bool global_frame(std::uint8_t frame) {
    return frame == mav::kFrameGlobal || frame == mav::kFrameGlobalRelativeAlt ||
           frame == mav::kFrameGlobalInt || frame == mav::kFrameGlobalRelativeAltInt;
}

}  // namespace

std::vector<std::string> statustext_lines(std::string_view reason) {
    std::vector<std::string> lines;
    std::string line;
    while (!reason.empty()) {
        const auto space = reason.find(' ');
        auto word = reason.substr(0, space);
        reason = space == std::string_view::npos ? std::string_view{} : reason.substr(space + 1);
        while (word.size() > kTextLength) {  // no space to cut at
            if (!line.empty()) {
                lines.push_back(std::exchange(line, {}));
            }
            lines.emplace_back(word.substr(0, kTextLength));
            word.remove_prefix(kTextLength);
        }
        if (!line.empty() && line.size() + 1 + word.size() > kTextLength) {
            lines.push_back(std::exchange(line, {}));
        }
        if (!line.empty()) {
            line += ' ';
        }
        line += word;
    }
    if (!line.empty()) {
        lines.push_back(std::move(line));
    }
    return lines;
}

MissionReceiver::MissionReceiver(std::uint8_t autopilot_sysid, std::uint8_t autopilot_compid,
                                 MissionReceiverConfig config)
    : sysid_(autopilot_sysid), config_(config), answers_(autopilot_sysid, autopilot_compid) {}

bool MissionReceiver::handle_frame(const mav::Frame& f, TimePoint now) {
    auto ours = [&](std::uint8_t target_system, std::uint8_t mission_type) {
        return (target_system == sysid_ || target_system == 0) && mission_type == mav::kMissionTypeMission;
    };
    switch (f.msgid) {
        case mav::MissionCount::kId: {
            const auto m = mav::decode_payload<mav::MissionCount>(f.payload_view());
            if (!ours(m.target_system, m.mission_type)) {
                return false;
            }
            const bool same_peer = f.sysid == peer_sysid_ && f.compid == peer_compid_;
            if (step_ == Step::AwaitVerdict || (step_ == Step::Receiving && !same_peer)) {
                ack(f.sysid, f.compid, mav::kMissionDenied);
                text("airseg: another mission upload is in progress");
                return true;
            }
            peer_sysid_ = f.sysid;
            peer_compid_ = f.compid;
            if (m.count < 2) {
                step_ = Step::Idle;
                end(mav::kMissionDenied, "airseg: the mission has no waypoints");
                return true;
            }
            if (m.count > kMaxItems) {
                step_ = Step::Idle;
                ++refused_too_large_;
                end(mav::kMissionNoSpace, "airseg: " + std::to_string(m.count) + " items is more than " +
                                              std::to_string(kMaxItems) + " (home included)");
                return true;
            }
            step_ = Step::Receiving;
            count_ = m.count;
            next_ = 0;
            use_int_ = true;
            items_.clear();
            attempts_ = 0;
            request(now);
            return true;
        }
        case mav::MissionItemInt::kId: {
            const auto m = mav::decode_payload<mav::MissionItemInt>(f.payload_view());
            if (!ours(m.target_system, m.mission_type)) {
                return false;
            }
            on_item(f.sysid, f.compid, m, true, now);
            return true;
        }
        case mav::MissionItem::kId: {
            const auto m = mav::decode_payload<mav::MissionItem>(f.payload_view());
            if (!ours(m.target_system, m.mission_type)) {
                return false;
            }
            mav::MissionItemInt i;
            i.seq = m.seq;
            i.frame = m.frame;
            i.command = m.command;
            i.param1 = m.param1;
            i.x = static_cast<std::int32_t>(static_cast<double>(m.x) * 1e7);
            i.y = static_cast<std::int32_t>(static_cast<double>(m.y) * 1e7);
            i.z = m.z;
            on_item(f.sysid, f.compid, i, false, now);
            return true;
        }
        default:
            return false;
    }
}

void MissionReceiver::on_item(std::uint8_t sysid, std::uint8_t compid, const mav::MissionItemInt& item,
                              bool as_int, TimePoint now) {
    if (step_ != Step::Receiving || sysid != peer_sysid_ || compid != peer_compid_ || item.seq != next_) {
        return;  // a duplicate or a stray: the pending request is repeated on its timeout
    }
    use_int_ = as_int;
    if (item.seq != 0) {
        const auto where = "item " + std::to_string(item.seq) + ": ";
        MissionItem out;
        out.lat = item.x * 1e-7;
        out.lon = item.y * 1e-7;
        bool position = true;
        switch (item.command) {
            case mav::kCmdNavWaypoint:
                break;
            case mav::kCmdNavLoiterTime:
                out.hold_s = static_cast<double>(item.param1);
                break;
            case mav::kCmdNavLoiterUnlim:
                out.kind = MissionItem::Kind::Stop;
                break;
            case mav::kCmdDoChangeSpeed:
                position = false;
                break;
            default:
                step_ = Step::Idle;
                end(mav::kMissionUnsupported,
                    "airseg: " + where + command_name(item.command) + " has no flight plan equivalent");
                return;
        }
        if (position) {
            if (!global_frame(item.frame)) {
                step_ = Step::Idle;
                end(mav::kMissionUnsupportedFrame, "airseg: " + where + "frame " +
                                                       std::to_string(item.frame) +
                                                       " is not global (0, 3, 5, 6)");
                return;
            }
            items_.push_back(out);
        }
    }
    ++next_;
    attempts_ = 0;
    if (next_ < count_) {
        request(now);
        return;
    }
    step_ = Step::AwaitVerdict;
    deadline_ = kNever;
    if (items_.empty()) {
        step_ = Step::Idle;
        end(mav::kMissionDenied, "airseg: the mission has no waypoints");
        return;
    }
    complete_ = ReceivedMission{peer_sysid_, peer_compid_, std::move(items_)};
    items_.clear();
}

void MissionReceiver::request(TimePoint now) {
    auto send = [&](auto r) {
        r.target_system = peer_sysid_;
        r.target_component = peer_compid_;
        r.seq = next_;
        r.mission_type = mav::kMissionTypeMission;
        out_.push_back({decltype(r)::kId, ForwardedFrame::Delivery::Reliable, answers_.encode(r)});
    };
    if (use_int_) {
        send(mav::MissionRequestInt{});
    } else {
        send(mav::MissionRequest{});
    }
    deadline_ = now + config_.request_timeout;
}

void MissionReceiver::handle_timeout(TimePoint now) {
    if (step_ != Step::Receiving || now < deadline_) {
        return;
    }
    if (attempts_ >= config_.retries) {
        step_ = Step::Idle;
        end(mav::kMissionOperationCancelled, "airseg: mission upload timed out");
        return;
    }
    ++attempts_;
    request(now);
}

TimePoint MissionReceiver::poll_timeout() const {
    return step_ == Step::Receiving ? deadline_ : kNever;
}

std::optional<ReceivedMission> MissionReceiver::poll_mission() {
    return std::exchange(complete_, std::nullopt);
}

void MissionReceiver::answer(bool accepted, std::string_view reason) {
    if (step_ != Step::AwaitVerdict) {
        return;
    }
    step_ = Step::Idle;
    complete_.reset();
    end(accepted ? mav::kMissionAccepted : mav::kMissionDenied, reason);
}

std::vector<ForwardedFrame> MissionReceiver::take_output() {
    return std::exchange(out_, {});
}

void MissionReceiver::ack(std::uint8_t sysid, std::uint8_t compid, std::uint8_t type) {
    mav::MissionAck a;
    a.target_system = sysid;
    a.target_component = compid;
    a.type = type;
    a.mission_type = mav::kMissionTypeMission;
    out_.push_back({mav::MissionAck::kId, ForwardedFrame::Delivery::Reliable, answers_.encode(a)});
}

void MissionReceiver::text(std::string_view reason) {
    auto lines = statustext_lines(reason);
    if (lines.size() > kMaxTextLines) {
        lines.resize(kMaxTextLines);
        lines.back() = lines.back().substr(0, kTextLength - 4) + " ...";
    }
    for (const auto& line : lines) {
        mav::Statustext t;
        t.severity = mav::kSeverityWarning;
        mav::set_text(t.text, line);
        out_.push_back({mav::Statustext::kId, ForwardedFrame::Delivery::Reliable, answers_.encode(t)});
    }
}

void MissionReceiver::end(std::uint8_t type, std::string_view reason) {
    deadline_ = kNever;
    items_.clear();
    ack(peer_sysid_, peer_compid_, type);
    text(reason);
}

}  // namespace airseg::autopilot
