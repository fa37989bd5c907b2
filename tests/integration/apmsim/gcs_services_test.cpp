// The simulated board's answers to a ground station's COMMAND_INT (DO_REPOSITION), TIMESYNC and MAVLink FTP
// (the packed parameter file), in simulated time.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "services/autopilot/mavftp.hpp"
#include "tests/integration/apmsim/sim_harness.hpp"
#include "tools/apmsim/param_pack.hpp"

namespace airseg::apmsim::test {
namespace {

constexpr std::uint16_t kDoReposition = 192;
const GeoPoint kPoint{41.2766, 1.9876};  // about 140 m north-east of home

mv::CommandInt reposition(std::uint8_t frame = mv::kFrameGlobalRelativeAltInt, float flags = 1) {
    mv::CommandInt c;
    c.command = kDoReposition;
    c.frame = frame;
    c.param1 = -1;  // the speed as it is
    c.param2 = flags;
    c.x = static_cast<std::int32_t>(kPoint.lat * 1e7);
    c.y = static_cast<std::int32_t>(kPoint.lon * 1e7);
    return c;
}

std::optional<std::uint8_t> command_result(SimHarness& h, const mv::CommandInt& c) {
    const std::size_t from = h.received.size();
    h.send(c);
    const auto ack = h.wait_for<mv::CommandAck>(
        [&](const mv::CommandAck& a) { return a.command == c.command; }, seconds(2), from);
    return ack ? std::optional<std::uint8_t>(ack->result) : std::nullopt;
}

TEST(ApmsimCommandInt, RepositionSwitchesToGuidedAndDrivesTowardThePoint) {
    SimHarness h;
    h.boot_armed();
    ASSERT_EQ(h.sim.state().mode, RoverMode::Manual);
    // Outside GUIDED without the change-mode flag: denied, as ArduPilot Rover does.
    EXPECT_EQ(command_result(h, reposition(mv::kFrameGlobalRelativeAltInt, 0)), mv::kResultDenied);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Manual);
    // A frame that is no global position, or a point at 0,0: denied.
    EXPECT_EQ(command_result(h, reposition(1 /* LOCAL_NED */)), mv::kResultDenied);
    auto nowhere = reposition();
    nowhere.x = 0;
    nowhere.y = 0;
    EXPECT_EQ(command_result(h, nowhere), mv::kResultDenied);

    const double before = distance_m(h.sim.state().position, kPoint);
    ASSERT_EQ(command_result(h, reposition()), mv::kResultAccepted);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Guided);
    ASSERT_TRUE(h.sim.state().target.has_value());
    EXPECT_LT(distance_m(*h.sim.state().target, kPoint), 0.05);
    h.run_for(seconds(10));
    const double after = distance_m(h.sim.state().position, kPoint);
    EXPECT_LT(after, before - 5) << "driving toward the point";
    // In GUIDED the flag is not needed; GLOBAL_INT is a frame it takes.
    EXPECT_EQ(command_result(h, reposition(mv::kFrameGlobalInt, 0)), mv::kResultAccepted);
    ASSERT_TRUE(h.run_until([&] { return distance_m(h.sim.state().position, kPoint) < 5; }, seconds(300)));
}

mv::SetPositionTargetGlobalInt position_target(std::uint16_t type_mask = 0x0DFC /* position only */) {
    mv::SetPositionTargetGlobalInt m;
    m.target_system = 1;
    m.coordinate_frame = mv::kFrameGlobalRelativeAltInt;
    m.type_mask = type_mask;
    m.lat_int = static_cast<std::int32_t>(kPoint.lat * 1e7);
    m.lon_int = static_cast<std::int32_t>(kPoint.lon * 1e7);
    return m;
}

// As ArduPilot's "Rover Commands in Guided Mode": a position target drives the rover in GUIDED; outside it,
// without a position, or in a frame that is no global position, nothing happens (and nothing is answered).
TEST(ApmsimSetPositionTarget, APositionInGuidedDrivesTheRoverAndIsIgnoredElsewhere) {
    SimHarness h;
    h.boot_armed();
    ASSERT_EQ(h.sim.state().mode, RoverMode::Manual);
    const auto ignored_before = h.sim.counters().frames_ignored;
    h.send(position_target());
    h.run_for(seconds(1));
    EXPECT_FALSE(h.sim.state().target.has_value()) << "outside GUIDED";
    EXPECT_EQ(h.sim.counters().frames_ignored, ignored_before + 1);

    h.set_mode(RoverMode::Guided);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Guided; }, seconds(2)));
    auto velocity_only = position_target(0x0DE7);
    h.send(velocity_only);
    auto local = position_target();
    local.coordinate_frame = 1;  // MAV_FRAME_LOCAL_NED
    h.send(local);
    h.run_for(seconds(1));
    EXPECT_FALSE(h.sim.state().target.has_value()) << "no position, or no global frame";

    const double before = distance_m(h.sim.state().position, kPoint);
    const std::size_t from = h.received.size();
    h.send(position_target());
    h.run_for(seconds(10));
    ASSERT_TRUE(h.sim.state().target.has_value());
    EXPECT_LT(distance_m(*h.sim.state().target, kPoint), 0.05);
    EXPECT_LT(distance_m(h.sim.state().position, kPoint), before - 5) << "driving toward the point";
    EXPECT_TRUE(h.all<mv::CommandAck>(from).empty()) << "a target is not answered";
}

TEST(ApmsimCommandInt, OtherCommandsAreHandledAsTheirCommandLongForm) {
    SimHarness h;
    h.boot();
    mv::CommandInt arm;
    arm.command = mv::kCmdComponentArmDisarm;
    arm.param1 = 1;
    EXPECT_EQ(command_result(h, arm), mv::kResultAccepted);
    EXPECT_TRUE(h.sim.state().armed);
}

TEST(ApmsimTimesync, ARequestIsAnsweredWithTheBoardsTimeAndTheRequestersEchoed) {
    SimHarness h;
    h.boot();
    h.run_for(seconds(3));
    mv::Timesync request;
    request.ts1 = 987'654'321'000;
    const std::size_t from = h.received.size();
    h.send(request);
    const auto reply = h.wait_for<mv::Timesync>(seconds(1), from);
    ASSERT_TRUE(reply.has_value());
    EXPECT_EQ(reply->ts1, request.ts1);
    EXPECT_EQ(reply->target_system, 255);
    EXPECT_EQ(reply->target_component, 190);
    // Time since boot in nanoseconds: the boot took a few seconds, and the answer came now.
    const auto since_boot_ns = static_cast<std::int64_t>(h.sim.state().time_boot_ms) * 1'000'000;
    EXPECT_NEAR(static_cast<double>(reply->tc1), static_cast<double>(since_boot_ns), 2e6);
    EXPECT_GT(reply->tc1, 3'000'000'000);
    // A reply (tc1 set) is not a request.
    mv::Timesync answer;
    answer.tc1 = 5;
    answer.ts1 = 6;
    const std::size_t after = h.received.size();
    h.send(answer);
    EXPECT_FALSE(h.wait_for<mv::Timesync>(seconds(1), after).has_value());
}

/// A MAVFTP client of the simulated board.
struct FtpClient {
    SimHarness& h;
    std::uint16_t seq = 0;

    std::vector<ftp::Packet> request(ftp::Packet p, std::size_t replies = 1) {
        p.seq = seq;
        mv::FileTransferProtocol m;
        m.target_system = 1;
        m.target_component = 1;
        m.payload = ftp::encode(p);
        const std::size_t from = h.received.size();
        h.send(m);
        std::vector<ftp::Packet> out;
        h.run_until(
            [&] {
                out.clear();
                for (const auto& r : h.all<mv::FileTransferProtocol>(from)) {
                    out.push_back(ftp::decode(r.payload));
                }
                return out.size() >= replies;
            },
            seconds(2));
        if (!out.empty()) {
            seq = out.back().seq;
        }
        return out;
    }
    static ftp::Packet op(ftp::Opcode o, std::string_view path = {}, std::uint32_t offset = 0,
                          std::uint8_t size = 0) {
        return ftp::request(o, path, offset, size);
    }
    static std::uint32_t u32(const ftp::Packet& p) {
        return std::uint32_t{p.data[0]} | std::uint32_t{p.data[1]} << 8 | std::uint32_t{p.data[2]} << 16 |
               std::uint32_t{p.data[3]} << 24;
    }
};

bool is_nak(const std::vector<ftp::Packet>& r, ftp::Error e) {
    return r.size() == 1 && r[0].opcode == ftp::Opcode::Nak && r[0].size >= 1 &&
           r[0].data[0] == static_cast<std::uint8_t>(e);
}

void expect_table(const std::vector<std::uint8_t>& file, const ParamTable& table) {
    const auto unpacked = unpack_params(file);
    ASSERT_TRUE(unpacked.has_value());
    EXPECT_EQ(unpacked->total, table.size());
    ASSERT_EQ(unpacked->params.size(), table.size());
    for (std::size_t i = 0; i < table.size(); ++i) {
        EXPECT_EQ(unpacked->params[i].name, table.at(i).name);
        EXPECT_EQ(unpacked->params[i].type, table.at(i).type) << table.at(i).name;
        EXPECT_FLOAT_EQ(unpacked->params[i].value, table.at(i).value) << table.at(i).name;
    }
}

TEST(ApmsimFtp, TheParameterFileIsReadWholeWithReadFileAndItsParametersAreTheBoards) {
    SimHarness h;
    h.boot();
    ASSERT_TRUE(h.sim.params().set("CRUISE_SPEED", 3.25F));
    FtpClient c{h};
    using Op = ftp::Opcode;
    const auto listed = c.request(FtpClient::op(Op::ListDirectory, "@PARAM"));
    ASSERT_EQ(listed.size(), 1u);
    ASSERT_EQ(listed[0].opcode, Op::Ack);
    const std::string entry = std::string(listed[0].path());
    EXPECT_EQ(entry.rfind("Fparam.pck\t", 0), 0u) << entry;
    EXPECT_TRUE(is_nak(c.request(FtpClient::op(Op::ListDirectory, "@PARAM", 1)), ftp::Error::Eof));
    EXPECT_TRUE(is_nak(c.request(FtpClient::op(Op::ListDirectory, "@NOPE")), ftp::Error::FileNotFound));

    const auto opened = c.request(FtpClient::op(Op::OpenFileRO, "@PARAM/param.pck"));
    ASSERT_EQ(opened.size(), 1u);
    ASSERT_EQ(opened[0].opcode, Op::Ack);
    EXPECT_EQ(opened[0].req_opcode, Op::OpenFileRO);
    const std::uint32_t size = FtpClient::u32(opened[0]);
    EXPECT_EQ(entry, "Fparam.pck\t" + std::to_string(size));
    EXPECT_TRUE(is_nak(c.request(FtpClient::op(Op::OpenFileRO, "@PARAM/param.pck")),
                       ftp::Error::NoSessionsAvailable));

    std::vector<std::uint8_t> file;
    while (file.size() < size) {
        auto read = FtpClient::op(Op::ReadFile, {}, static_cast<std::uint32_t>(file.size()), 239);
        read.session = opened[0].session;
        const auto r = c.request(read);
        ASSERT_EQ(r.size(), 1u);
        ASSERT_EQ(r[0].opcode, Op::Ack) << file.size();
        ASSERT_EQ(r[0].offset, file.size());
        file.insert(file.end(), r[0].bytes().begin(), r[0].bytes().end());
    }
    EXPECT_EQ(file.size(), size);
    expect_table(file, h.sim.params());
    auto past = FtpClient::op(Op::ReadFile, {}, size, 239);
    EXPECT_TRUE(is_nak(c.request(past), ftp::Error::Eof));
    auto other_size = FtpClient::op(Op::ReadFile, {}, 0, 100);
    EXPECT_TRUE(is_nak(c.request(other_size), ftp::Error::Fail)) << "one read size per open";
    auto wrong_session = FtpClient::op(Op::ReadFile, {}, 0, 239);
    wrong_session.session = 3;
    EXPECT_TRUE(is_nak(c.request(wrong_session), ftp::Error::InvalidSession));

    auto terminate = FtpClient::op(Op::TerminateSession);
    ASSERT_EQ(c.request(terminate).at(0).opcode, Op::Ack);
    EXPECT_TRUE(is_nak(c.request(FtpClient::op(Op::ReadFile, {}, 0, 239)), ftp::Error::InvalidSession));
    EXPECT_TRUE(is_nak(c.request(FtpClient::op(Op::OpenFileRO, "@SYS/nothing")), ftp::Error::FileNotFound));
    EXPECT_TRUE(
        is_nak(c.request(FtpClient::op(Op::OpenFileWO, "@PARAM/param.pck")), ftp::Error::UnknownCommand));
    EXPECT_TRUE(
        is_nak(c.request(FtpClient::op(Op::CalcFileCRC32, "@PARAM/param.pck")), ftp::Error::UnknownCommand));
}

TEST(ApmsimFtp, ABurstReadSendsTheFileInBlocksOfTheRequestedSize) {
    SimHarness h;
    h.boot();
    FtpClient c{h};
    using Op = ftp::Opcode;
    ASSERT_EQ(c.request(FtpClient::op(Op::ResetSessions)).at(0).opcode, Op::Ack);
    const auto opened = c.request(FtpClient::op(Op::OpenFileRO, "@PARAM/param.pck?start=10&count=40"));
    ASSERT_EQ(opened.at(0).opcode, Op::Ack);
    // Blocks of 110 bytes, as ArduPilot's extension lets a ground station ask over a SiK radio: the file
    // packed for that size (no parameter crosses a block), so longer than told at the open.
    const auto told = FtpClient::u32(opened[0]);
    std::vector<std::uint8_t> file;
    for (int burst = 0; burst < 10; ++burst) {
        const std::size_t from = h.received.size();
        auto read = FtpClient::op(Op::BurstReadFile, {}, static_cast<std::uint32_t>(file.size()), 110);
        h.send([&] {
            mv::FileTransferProtocol m;
            m.target_system = 1;
            m.payload = ftp::encode(read);
            return m;
        }());
        h.run_for(seconds(1));
        const auto replies = h.all<mv::FileTransferProtocol>(from);
        ASSERT_FALSE(replies.empty());
        const auto last = ftp::decode(replies.back().payload);
        if (last.opcode == Op::Nak) {
            EXPECT_EQ(last.data[0], static_cast<std::uint8_t>(ftp::Error::Eof));
            break;
        }
        for (const auto& r : replies) {
            const auto p = ftp::decode(r.payload);
            ASSERT_EQ(p.opcode, Op::Ack);
            ASSERT_EQ(p.offset, file.size());
            EXPECT_LE(p.size, 110);
            file.insert(file.end(), p.bytes().begin(), p.bytes().end());
        }
        EXPECT_EQ(last.burst_complete, 1);
    }
    EXPECT_GE(file.size(), told);
    const auto unpacked = unpack_params(file);
    ASSERT_TRUE(unpacked.has_value());
    ASSERT_EQ(unpacked->params.size(), 40u);
    EXPECT_EQ(unpacked->total, h.sim.params().size());
    EXPECT_EQ(unpacked->params[0].name, h.sim.params().at(10).name);
    EXPECT_EQ(unpacked->params[39].name, h.sim.params().at(49).name);
}

TEST(ParamPack, NoParameterCrossesABlockAndNamesShareTheirPrefix) {
    const auto table = ParamTable::rover_defaults();
    for (const std::size_t block : {std::size_t{32}, std::size_t{110}, std::size_t{239}}) {
        const auto file = pack_params(table, block);
        expect_table(file, table);
        // Walk the blocks: each starts at a parameter or padding, never inside one.
        std::size_t at = 6;
        std::string previous;
        std::size_t entries = 0;
        while (entries < table.size()) {
            while (file.at(at) == 0) {
                ++at;
            }
            const std::size_t rest = (file[at + 1] >> 4) + 1;
            const std::size_t size = (file[at] & 0x0F) == 1 ? 1 : (file[at] & 0x0F) == 2 ? 2 : 4;
            const std::size_t end = at + 2 + rest + size;
            EXPECT_EQ(at / block, (end - 1) / block) << "parameter " << entries << " crosses block " << block;
            at = end;
            ++entries;
        }
    }
    // The header, then a first block with nothing in common with a previous name.
    const auto file = pack_params(table, 239);
    EXPECT_EQ(file[0], 0x1B);
    EXPECT_EQ(file[1], 0x67);
    EXPECT_EQ(file[7] & 0x0F, 0);
    // A file that is not one: nothing.
    EXPECT_FALSE(unpack_params(std::vector<std::uint8_t>{0x1B, 0x67, 5, 0, 5, 0, 4}).has_value());
    EXPECT_FALSE(unpack_params(std::vector<std::uint8_t>{1, 2, 3}).has_value());
}

}  // namespace
}  // namespace airseg::apmsim::test
