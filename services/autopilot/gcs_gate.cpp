#include "services/autopilot/gcs_gate.hpp"

#include <array>
#include <optional>
#include <string_view>

#include "services/autopilot/mavftp.hpp"
#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::autopilot {

namespace mav = airseg::mavlink;

namespace {

constexpr std::array<const char*, 3> kRefusal{
    "airseg: ground station mission write refused",
    "airseg: missions are flight plans, kept on board",
    "airseg: load one with: airsegctl plan load FILE",
};

struct Target {
    std::uint8_t system = 0;
    std::uint8_t component = 0;
    std::uint8_t mission_type = 0;
};

template <class M>
Target target_of(const mav::Frame& f) {
    const auto m = mav::decode_payload<M>(f.payload_view());
    if constexpr (requires { m.mission_type; }) {
        return {m.target_system, m.target_component, m.mission_type};
    } else {
        return {m.target_system, m.target_component, mav::kMissionTypeMission};
    }
}

/// The addressee of a mission write, or nothing when the frame is none.
std::optional<Target> mission_write(const mav::Frame& f) {
    switch (f.msgid) {
        case mav::MissionCount::kId:
            return target_of<mav::MissionCount>(f);
        case mav::MissionItem::kId:
            return target_of<mav::MissionItem>(f);
        case mav::MissionItemInt::kId:
            return target_of<mav::MissionItemInt>(f);
        case mav::MissionClearAll::kId:
            return target_of<mav::MissionClearAll>(f);
        case mav::MissionSetCurrent::kId:
            return target_of<mav::MissionSetCurrent>(f);
        case mav::MissionWritePartialList::kId:
            return target_of<mav::MissionWritePartialList>(f);
        default:
            return std::nullopt;
    }
}

/// Commands that move or rewrite the mission, refused in COMMAND_LONG and COMMAND_INT alike: the command
/// form of MISSION_SET_CURRENT moves the mission as much as the message does.
bool command_writes_mission(std::uint16_t command) {
    return command == mav::kCmdDoSetMissionCurrent;
}

/// A path of ArduPilot's @MISSION file system whose writing replaces the mission. Its fence.dat and
/// rally.dat pass, as fence and rally uploads by message do. The path is judged as resolved: empty and "."
/// segments dropped, ".." taking the one before it (none above the top), so no spelling of it reaches
/// @MISSION unseen ("/@MISSION//mission.dat", "@PARAM/../@MISSION/mission.dat").
bool is_mission_file(std::string_view path) {
    constexpr std::size_t kMaxSegments = 16;  // a 239-byte path that needs more is refused, not resolved
    std::array<std::string_view, kMaxSegments> segments{};
    std::size_t depth = 0;
    while (!path.empty()) {
        const std::size_t slash = path.find('/');
        const std::string_view segment = path.substr(0, slash);
        path.remove_prefix(slash == std::string_view::npos ? path.size() : slash + 1);
        if (segment.empty() || segment == ".") {
            continue;
        }
        if (segment == "..") {
            depth -= depth > 0 ? 1 : 0;
            continue;
        }
        if (depth == kMaxSegments) {
            return true;
        }
        segments[depth++] = segment;
    }
    constexpr std::string_view kRoot = "@MISSION";
    if (depth == 0 || segments[0].substr(0, kRoot.size()) != kRoot) {
        return false;
    }
    const bool fence_or_rally =
        depth == 2 && segments[0] == kRoot && (segments[1] == "fence.dat" || segments[1] == "rally.dat");
    return !fence_or_rally;
}

/// A MAVFTP request that would create, change or remove a mission file.
bool ftp_writes_mission(const mavftp::Packet& p) {
    if (!mavftp::writes_path(p.opcode)) {
        return false;
    }
    if (is_mission_file(p.path())) {
        return true;
    }
    // Rename: "old\0new"; either end in @MISSION moves the mission.
    const auto first = p.path();
    return p.opcode == mavftp::Opcode::Rename && is_mission_file(p.path(first.size() + 1));
}

}  // namespace

ForwardedFrame::Delivery delivery_of(std::uint32_t msgid) {
    switch (msgid) {
        case mav::ParamValue::kId:
        case mav::CommandAck::kId:
        case mav::Statustext::kId:
        case mav::AutopilotVersion::kId:
        case mav::MissionItem::kId:
        case mav::MissionRequest::kId:
        case mav::MissionCount::kId:
        case mav::MissionAck::kId:
        case mav::MissionItemReached::kId:
        case mav::MissionRequestInt::kId:
        case mav::MissionItemInt::kId:
        // Each MAVFTP reply and TIMESYNC reply answers one request: none may stand in for another.
        case mav::FileTransferProtocol::kId:
        case mav::Timesync::kId:
            return ForwardedFrame::Delivery::Reliable;
        default:
            // MISSION_CURRENT is telemetry: the current slot, repeated at a stream rate.
            return ForwardedFrame::Delivery::Freshest;
    }
}

ForwardedFrame forwarded(std::span<const std::uint8_t> frame) {
    std::uint32_t id = 0;
    if (frame.size() >= mav::kHeaderLengthV2 && frame[0] == mav::kMagicV2) {
        id = std::uint32_t{frame[7]} | std::uint32_t{frame[8]} << 8 | std::uint32_t{frame[9]} << 16;
    } else if (frame.size() >= mav::kHeaderLengthV1) {
        id = frame[5];
    }
    return {id, delivery_of(id), {frame.begin(), frame.end()}};
}

std::span<const char* const> mission_refusal_texts() {
    return kRefusal;
}

GcsGate::GcsGate(std::uint8_t autopilot_sysid, std::uint8_t autopilot_compid)
    : sysid_(autopilot_sysid), answers_(autopilot_sysid, autopilot_compid) {}

GcsGate::Output GcsGate::from_ground(std::span<const std::uint8_t> frames, TimePoint now) {
    Output out;
    mav::Parser parser;  // a fresh one each time: the frames are whole, and ground stations' links differ
    auto on_frame = [&](const mav::Frame& f) {
        if (!f.checksum_verified) {
            ++stats_.invalid;
            return;
        }
        ++stats_.frames;
        if (uploads_ && uploads_->handle_frame(f, now)) {
            ++stats_.upload_frames;
            return;
        }
        if (refuse(f, out)) {
            return;
        }
        out.to_autopilot.push_back(mav::reencode(f));
        ++stats_.passed;
    };
    parser.push(frames, on_frame);
    parser.finish(on_frame);
    const auto& ps = parser.stats();
    stats_.invalid += ps.bad_checksum + ps.truncated + ps.incompat_rejected + (ps.garbage_bytes > 0 ? 1 : 0);
    return out;
}

bool GcsGate::addressed_to_autopilot(std::uint8_t target_system) const {
    return target_system == sysid_ || target_system == 0;
}

bool GcsGate::refuse(const mav::Frame& f, Output& out) {
    if (f.msgid == mav::CommandLong::kId || f.msgid == mav::CommandInt::kId) {
        std::uint16_t command = 0;
        std::uint8_t target = 0;
        if (f.msgid == mav::CommandLong::kId) {
            const auto cmd = mav::decode_payload<mav::CommandLong>(f.payload_view());
            command = cmd.command;
            target = cmd.target_system;
        } else {
            const auto cmd = mav::decode_payload<mav::CommandInt>(f.payload_view());
            command = cmd.command;
            target = cmd.target_system;
        }
        if (!command_writes_mission(command) || !addressed_to_autopilot(target)) {
            return false;
        }
        mav::CommandAck ack;
        ack.command = command;
        ack.result = mav::kResultDenied;
        ack.target_system = f.sysid;
        ack.target_component = f.compid;
        out.to_ground.push_back(
            {mav::CommandAck::kId, ForwardedFrame::Delivery::Reliable, answers_.encode(ack)});
    } else if (f.msgid == mav::FileTransferProtocol::kId) {
        const auto m = mav::decode_payload<mav::FileTransferProtocol>(f.payload_view());
        const auto request = mavftp::decode(m.payload);
        if (!addressed_to_autopilot(m.target_system) || !ftp_writes_mission(request)) {
            return false;
        }
        mav::FileTransferProtocol nak;
        nak.target_system = f.sysid;
        nak.target_component = f.compid;
        nak.payload = mavftp::encode(mavftp::nak(request, mavftp::Error::FileProtected));
        out.to_ground.push_back(
            {mav::FileTransferProtocol::kId, ForwardedFrame::Delivery::Reliable, answers_.encode(nak)});
        ++stats_.ftp_refused;
    } else {
        const auto target = mission_write(f);
        if (!target || !addressed_to_autopilot(target->system) ||
            target->mission_type != mav::kMissionTypeMission) {
            return false;
        }
        mav::MissionAck ack;
        ack.target_system = f.sysid;
        ack.target_component = f.compid;
        ack.type = mav::kMissionDenied;
        ack.mission_type = target->mission_type;
        out.to_ground.push_back(
            {mav::MissionAck::kId, ForwardedFrame::Delivery::Reliable, answers_.encode(ack)});
    }
    ++stats_.missions_refused;
    for (const char* line : kRefusal) {
        mav::Statustext text;
        text.severity = mav::kSeverityWarning;
        mav::set_text(text.text, line);
        out.to_ground.push_back(
            {mav::Statustext::kId, ForwardedFrame::Delivery::Reliable, answers_.encode(text)});
    }
    return true;
}

}  // namespace airseg::autopilot
