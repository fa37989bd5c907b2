// What the gate lets through besides the mission protocol: COMMAND_INT under COMMAND_LONG's rules, TIMESYNC,
// SET_POSITION_TARGET_GLOBAL_INT, and MAVFTP but for writes to the @MISSION files.
#include <gtest/gtest.h>

#include <cstring>
#include <string_view>

#include "services/autopilot/gcs_gate.hpp"
#include "services/autopilot/mavftp.hpp"
#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/unit/autopilot/gcs_gate_rig.hpp"

namespace airseg::autopilot {
namespace {

namespace mav = airseg::mavlink;

using gate_test::parse;
using gate_test::Rig;

mav::FileTransferProtocol ftp_request(mavftp::Opcode op, std::string_view path, std::uint8_t target = 1) {
    mavftp::Packet p;
    p.seq = 7;
    p.opcode = op;
    std::memcpy(p.data.data(), path.data(), path.size());
    p.size = static_cast<std::uint8_t>(path.size());
    mav::FileTransferProtocol m;
    m.target_system = target;
    m.target_component = 1;
    m.payload = mavftp::encode(p);
    return m;
}

TEST(GcsGatePassage, CommandIntTimesyncAndPositionTargetsReachTheAutopilotUnchanged) {
    Rig rig;
    mav::CommandInt reposition;
    reposition.target_system = 1;
    reposition.target_component = 1;
    reposition.command = 192;  // MAV_CMD_DO_REPOSITION
    reposition.frame = mav::kFrameGlobalRelativeAltInt;
    reposition.x = 412'760'000;
    reposition.y = 19'870'000;
    mav::Timesync sync;
    sync.ts1 = 123'456'789;
    mav::SetPositionTargetGlobalInt target;
    target.target_system = 1;
    target.lat_int = 412'760'000;
    target.type_mask = 0x0DF8;
    for (const auto& frame : {rig.gcs.encode(reposition), rig.gcs.encode(sync), rig.gcs.encode(target)}) {
        const auto out = rig.gate.from_ground(frame);
        EXPECT_TRUE(out.to_ground.empty());
        ASSERT_EQ(out.to_autopilot.size(), 1u);
        EXPECT_EQ(out.to_autopilot[0], frame) << "passed byte for byte";
    }
    EXPECT_EQ(rig.gate.stats().passed, 3u);
    EXPECT_EQ(rig.gate.stats().missions_refused, 0u);
}

TEST(GcsGatePassage, CommandIntThatMovesTheMissionIsDeniedAsCommandLongIs) {
    Rig rig;
    mav::CommandInt set_current;
    set_current.target_system = 1;
    set_current.command = mav::kCmdDoSetMissionCurrent;
    set_current.param1 = 3;
    const auto out = rig.gate.from_ground(rig.gcs.encode(set_current));
    EXPECT_TRUE(out.to_autopilot.empty());
    ASSERT_EQ(out.to_ground.size(), 1 + mission_refusal_texts().size());
    const auto frames = parse(out.to_ground[0].bytes);
    ASSERT_EQ(frames.size(), 1u);
    ASSERT_EQ(frames[0].msgid, mav::CommandAck::kId);
    const auto ack = mav::decode_payload<mav::CommandAck>(frames[0].payload_view());
    EXPECT_EQ(ack.command, mav::kCmdDoSetMissionCurrent);
    EXPECT_EQ(ack.result, mav::kResultDenied);
    EXPECT_EQ(ack.target_system, 254);
    EXPECT_EQ(rig.gate.stats().missions_refused, 1u);

    // Addressed to another vehicle: not ours to refuse.
    set_current.target_system = 9;
    EXPECT_EQ(rig.gate.from_ground(rig.gcs.encode(set_current)).to_autopilot.size(), 1u);
}

TEST(GcsGatePassage, MavftpReadsPassAndWritesToTheMissionAreRefusedWithANak) {
    Rig rig;
    using Op = mavftp::Opcode;
    // Reads, parameter files, sessions and writes elsewhere pass.
    for (const auto& m :
         {ftp_request(Op::OpenFileRO, "@PARAM/param.pck"), ftp_request(Op::ListDirectory, "@PARAM"),
          ftp_request(Op::OpenFileRO, "@MISSION/mission.dat"),
          ftp_request(Op::CreateFile, "@MISSION/fence.dat"),
          ftp_request(Op::OpenFileWO, "/@MISSION/./rally.dat"),
          ftp_request(Op::OpenFileWO, "@MISSION/../APM/mission.dat"),
          ftp_request(Op::OpenFileWO, "/APM/scripts/a.lua"), ftp_request(Op::ResetSessions, ""),
          ftp_request(Op::OpenFileWO, "@MISSION/mission.dat", 9)}) {
        const auto out = rig.gate.from_ground(rig.gcs.encode(m));
        EXPECT_EQ(out.to_autopilot.size(), 1u) << static_cast<int>(mavftp::decode(m.payload).opcode);
        EXPECT_TRUE(out.to_ground.empty());
    }
    // Every way of writing the mission file is answered as the autopilot would refuse a protected file.
    for (const auto& m :
         {ftp_request(Op::OpenFileWO, "@MISSION/mission.dat"),
          ftp_request(Op::CreateFile, "@MISSION/mission.dat"),
          ftp_request(Op::CreateFile, "/@MISSION/mission.dat"),
          ftp_request(Op::CreateFile, "//@MISSION//mission.dat"),
          ftp_request(Op::OpenFileWO, "@PARAM/../@MISSION/mission.dat"),
          ftp_request(Op::OpenFileWO, "../../@MISSION/./mission.dat"),
          ftp_request(Op::OpenFileWO, "@MISSION/fence.dat/../mission.dat"),
          ftp_request(Op::TruncateFile, "@MISSION/mission.dat"),
          ftp_request(Op::RemoveFile, "@MISSION/mission.dat"), ftp_request(Op::CreateDirectory, "@MISSION/x"),
          ftp_request(Op::Rename, std::string_view("a.dat\0@MISSION/mission.dat", 26)),
          ftp_request(Op::OpenFileWO, "@MISSION/mission.dat", 0)}) {
        const auto request = mavftp::decode(m.payload);
        const auto out = rig.gate.from_ground(rig.gcs.encode(m));
        EXPECT_TRUE(out.to_autopilot.empty()) << request.path();
        ASSERT_EQ(out.to_ground.size(), 1 + mission_refusal_texts().size());
        EXPECT_EQ(out.to_ground[0].delivery, ForwardedFrame::Delivery::Reliable);
        const auto frames = parse(out.to_ground[0].bytes);
        ASSERT_EQ(frames.size(), 1u);
        ASSERT_EQ(frames[0].msgid, mav::FileTransferProtocol::kId);
        EXPECT_EQ(frames[0].sysid, 1);
        const auto reply = mav::decode_payload<mav::FileTransferProtocol>(frames[0].payload_view());
        EXPECT_EQ(reply.target_system, 254);
        EXPECT_EQ(reply.target_component, 190);
        const auto nak = mavftp::decode(reply.payload);
        EXPECT_EQ(nak.opcode, Op::Nak);
        EXPECT_EQ(nak.req_opcode, request.opcode);
        EXPECT_EQ(nak.seq, 8) << "one on from the request's";
        ASSERT_EQ(nak.size, 1);
        EXPECT_EQ(nak.data[0], static_cast<std::uint8_t>(mavftp::Error::FileProtected));
    }
    EXPECT_EQ(rig.gate.stats().ftp_refused, 12u);
    EXPECT_EQ(rig.gate.stats().missions_refused, 12u);
}

TEST(GcsGatePassage, AMavftpSizeBeyondTheDataIsReadOnlyAsFarAsTheDataGoes) {
    Rig rig;
    auto m = ftp_request(mavftp::Opcode::OpenFileWO, "@MISSION/mission.dat");
    m.payload[4] = 255;  // size claims more than the 239 data bytes
    const auto out = rig.gate.from_ground(rig.gcs.encode(m));
    EXPECT_TRUE(out.to_autopilot.empty());
    EXPECT_EQ(rig.gate.stats().ftp_refused, 1u);
}

TEST(GcsGatePassage, AutopilotAnswersTheStationsWaitForTravelReliably) {
    EXPECT_EQ(delivery_of(mav::FileTransferProtocol::kId), ForwardedFrame::Delivery::Reliable);
    EXPECT_EQ(delivery_of(mav::Timesync::kId), ForwardedFrame::Delivery::Reliable);
    EXPECT_EQ(delivery_of(mav::CommandAck::kId), ForwardedFrame::Delivery::Reliable);
    EXPECT_EQ(delivery_of(mav::PositionTargetGlobalInt::kId), ForwardedFrame::Delivery::Freshest);
}

}  // namespace
}  // namespace airseg::autopilot
