// The rover2 firmware profile (APMrover2 2.4x on an APM 2.5) driven with raw MAVLink 1 frames in simulated
// time: each test checks one behaviour the simulator takes from the 2.x source (docs/simulators.md).
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/integration/apmsim/sim_harness.hpp"
#include "tools/apmsim/control.hpp"
#include "tools/apmsim/options.hpp"

namespace airseg::apmsim::test {
namespace {

constexpr std::uint8_t kSeverityLow = 1;  // the 2.x SEVERITY_LOW
constexpr std::uint8_t kSeverityHigh = 3;

RoverSimConfig rover2() {
    return RoverSimConfig::for_firmware(Firmware::Rover2);
}

/// A booted rover2 board and a MAVLink 1 ground station.
void boot_rover2(SimHarness& h) {
    h.gcs.set_version(mv::Version::V1);
    h.boot();
}

bool has_text(const std::vector<std::string>& texts, std::string_view needle) {
    return std::any_of(texts.begin(), texts.end(),
                       [&](const std::string& t) { return t.find(needle) != std::string::npos; });
}

std::vector<std::uint16_t> reached_seqs(const RoverSim& sim, std::size_t from = 0) {
    std::vector<std::uint16_t> seqs;
    for (std::size_t i = from; i < sim.reached().size(); ++i) {
        seqs.push_back(sim.reached()[i].seq);
    }
    return seqs;
}

std::optional<mv::MissionItem> download_item(SimHarness& h, std::uint16_t seq) {
    mv::MissionRequest r;
    r.seq = seq;
    const std::size_t from = h.received.size();
    h.send(r);
    return h.last<mv::MissionItem>(from);
}

std::optional<mv::CommandAck> command(SimHarness& h, std::uint16_t cmd, float p1 = 0, float p2 = 0) {
    mv::CommandLong c;
    c.command = cmd;
    c.param1 = p1;
    c.param2 = p2;
    const std::size_t from = h.received.size();
    h.send(c);
    return h.last<mv::CommandAck>(from);
}

TEST(ApmsimLegacyParser, MavlinkTwoIsNoiseThatCanSwallowTheNextFrame) {
    LegacyParser parser({mv::MissionRequestInt::kId});
    std::vector<mv::Frame> frames;
    const auto push = [&](const std::vector<std::uint8_t>& bytes) {
        parser.push(bytes, [&](const mv::Frame& f) { frames.push_back(f); });
    };
    mv::Encoder v1(255, 190, mv::Version::V1);
    mv::Encoder v2(255, 190, mv::Version::V2);
    mv::Heartbeat hb;
    hb.type = 6;
    push(v1.encode(hb));
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].version, mv::Version::V1);
    EXPECT_EQ(frames[0].msgid, mv::Heartbeat::kId);

    // A MAVLink 2 frame whose payload holds 0xFE: the 2.x receiver takes that byte for a start, reads the
    // next byte (200) as a length and swallows the good frame after it.
    mv::ParamSet p;
    p.target_system = 1;
    p.param_id[0] = static_cast<char>(0xFE);
    p.param_id[1] = static_cast<char>(200);
    p.param_id[2] = 'x';
    push(v2.encode(p));
    push(v1.encode(hb));
    EXPECT_EQ(frames.size(), 1u) << "the heartbeat went into the false candidate";
    EXPECT_EQ(parser.stats().v2_starts, 1u);
    std::vector<std::uint8_t> filler(300, 0);
    push(filler);
    EXPECT_EQ(parser.stats().bad_crc, 1u);
    push(v1.encode(hb));
    EXPECT_EQ(frames.size(), 2u) << "back in step after the false candidate";

    mv::MissionRequestInt ri;
    ri.target_system = 1;
    push(v1.encode(ri));
    EXPECT_EQ(frames.size(), 2u) << "no CRC_EXTRA for id 51 in the 2.x table";
    EXPECT_EQ(parser.stats().bad_crc, 2u);
}

TEST(ApmsimRover2, SendsMavlink1AndTakesMavlink2ForLineNoise) {
    SimHarness h(rover2());
    boot_rover2(h);
    ASSERT_FALSE(h.received.empty());
    for (const auto& r : h.received) {
        EXPECT_EQ(r.frame.version, mv::Version::V1);
    }
    mv::ParamRequestRead q;
    q.param_index = -1;
    mv::set_text(q.param_id, "WP_RADIUS");
    mv::Encoder v2(255, 190, mv::Version::V2);
    std::size_t from = h.received.size();
    h.send(q, &v2);
    h.run_for(seconds(2));
    EXPECT_FALSE(h.last<mv::ParamValue>(from)) << "a MAVLink 2 frame is noise to the 2.x receiver";
    EXPECT_EQ(h.sim.counters().mavlink2_ignored, 1u);

    from = h.received.size();
    h.send(q);
    const auto v = h.last<mv::ParamValue>(from);
    ASSERT_TRUE(v);
    EXPECT_EQ(mv::text_of(v->param_id), "WP_RADIUS");
    EXPECT_EQ(v->param_index, 65535) << "2.x echoes the request's index: -1 for a read by name";

    mv::set_text(q.param_id, "NO_SUCH_PARAM");
    from = h.received.size();
    h.send(q);
    EXPECT_TRUE(has_text(h.texts(from), "Unknown parameter NO_SUCH_PARAM"));

    SimHarness modern;
    modern.boot();
    mv::set_text(q.param_id, "WP_RADIUS");
    from = modern.received.size();
    modern.send(q, &v2);
    EXPECT_TRUE(modern.last<mv::ParamValue>(from)) << "the modern board reads MAVLink 2";
    EXPECT_EQ(modern.sim.counters().mavlink2_ignored, 0u);
}

TEST(ApmsimRover2, IntMissionMessagesAreNotUnderstood) {
    SimHarness h(rover2());
    boot_rover2(h);
    ASSERT_EQ(h.upload_float(to_float(line_mission(h.sim.config().home, 2, 20))), 0);

    mv::MissionRequestInt ri;
    ri.seq = 1;
    std::size_t from = h.received.size();
    h.send(ri);
    h.run_for(seconds(1));
    EXPECT_FALSE(h.last<mv::MissionItemInt>(from));
    EXPECT_FALSE(h.last<mv::MissionItem>(from));
    EXPECT_EQ(h.sim.counters().bad_checksum, 1u) << "2.x has no CRC_EXTRA for MISSION_REQUEST_INT";
    const auto item = download_item(h, 1);
    ASSERT_TRUE(item);
    EXPECT_EQ(item->seq, 1);

    // An upload answered with MISSION_ITEM_INT makes no progress: the board asks for the same item again.
    mv::MissionCount c;
    c.count = 2;
    from = h.received.size();
    h.send(c);
    const auto first = h.last<mv::MissionRequest>(from);
    ASSERT_TRUE(first);
    EXPECT_EQ(first->seq, 0);
    auto home = waypoint(h.sim.config().home, 0, 0);
    home.seq = 0;
    from = h.received.size();
    h.send(home);
    const auto again = h.wait_for<mv::MissionRequest>(seconds(1), from);
    ASSERT_TRUE(again);
    EXPECT_EQ(again->seq, 0);
    EXPECT_EQ(h.sim.counters().bad_checksum, 2u);
    EXPECT_TRUE(h.all<mv::MissionRequestInt>().empty()) << "2.x never asks for _INT items";
}

TEST(ApmsimRover2, FloatUploadIsStoredAsThe2xEepromKeepsIt) {
    SimHarness h(rover2());
    boot_rover2(h);
    const GeoPoint home = h.sim.config().home;
    std::vector<mv::MissionItem> items = to_float(line_mission(home, 2, 20));
    items[1].param1 = 5;                              // a hold time: 2.x does not keep it
    items.push_back(command_item(178, 0, 2.5F, -1));  // DO_CHANGE_SPEED
    items.push_back(to_float(waypoint(home, 60, 0)));
    std::size_t from = h.received.size();
    ASSERT_EQ(h.upload_float(items), 0);
    const auto requests = h.all<mv::MissionRequest>(from);
    ASSERT_EQ(requests.size(), items.size());
    EXPECT_EQ(requests[0].target_system, 0) << "no list request since boot: the requests go to 0/0";
    EXPECT_TRUE(has_text(h.texts(from), "flight plan received"));

    mv::MissionRequestList list;
    from = h.received.size();
    h.send(list);
    const auto count = h.last<mv::MissionCount>(from);
    ASSERT_TRUE(count);
    EXPECT_EQ(count->count, items.size());
    const auto wp1 = download_item(h, 1);
    ASSERT_TRUE(wp1);
    EXPECT_EQ(wp1->command, 16);
    EXPECT_EQ(wp1->frame, 3);
    EXPECT_EQ(wp1->param1, 0) << "param1 of a waypoint is not stored";
    EXPECT_NEAR(wp1->x, items[1].x, 1e-5);
    EXPECT_NEAR(wp1->z, h.sim.config().home_alt, 1e-4) << "a relative altitude comes back with home's added";
    const auto speed = download_item(h, 3);
    ASSERT_TRUE(speed);
    EXPECT_EQ(speed->command, 178);
    EXPECT_EQ(speed->param2, 2.0F) << "the speed is stored as a whole number";
    EXPECT_EQ(speed->param3, -1.0F);
    const auto past = download_item(h, 9);
    ASSERT_TRUE(past);
    EXPECT_EQ(past->command, 0) << "an index past the end is a blank item, not an error";

    from = h.received.size();
    ASSERT_EQ(h.upload_float(items), 0);
    EXPECT_EQ(h.all<mv::MissionRequest>(from).front().target_system, 255)
        << "after a list request the board asks the station that listed";
}

TEST(ApmsimRover2, UploadPatienceIsHalfASecondAndOneSecondOfSilence) {
    SimHarness h(rover2());
    boot_rover2(h);
    mv::MissionCount c;
    c.count = 3;
    const std::size_t from = h.received.size();
    const TimePoint t0 = h.now;
    h.send(c);
    EXPECT_EQ(h.sim.state().mission_count, 3u) << "CMD_TOTAL is saved with the count";
    h.run_for(seconds(3));
    std::vector<TimePoint> at;
    for (std::size_t i = from; i < h.received.size(); ++i) {
        if (auto r = mv::decode<mv::MissionRequest>(h.received[i].frame)) {
            EXPECT_EQ(r->seq, 0);
            at.push_back(h.received[i].at);
        }
    }
    ASSERT_EQ(at.size(), 2u);
    EXPECT_EQ(at[0], t0);
    EXPECT_EQ(at[1] - t0, milliseconds(500));
    EXPECT_FALSE(h.last<mv::MissionAck>(from)) << "2.x stops listening silently";
    EXPECT_EQ(h.sim.mission_stats().uploads_cancelled, 1u);
    auto late = to_float(waypoint(h.sim.config().home, 0, 0));
    late.seq = 0;
    h.send(late);
    ASSERT_TRUE(h.last<mv::MissionAck>(from));
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 1) << "MAV_MISSION_ERROR: not receiving";
}

TEST(ApmsimRover2, ItemInAFrameItCannotStoreIsRefusedAndAskedForAgain) {
    SimHarness h(rover2());
    boot_rover2(h);
    const GeoPoint home = h.sim.config().home;
    mv::MissionCount c;
    c.count = 3;
    std::size_t from = h.received.size();
    h.send(c);
    auto item0 = to_float(waypoint(home, 0, 0));
    item0.seq = 0;
    h.send(item0);
    ASSERT_EQ(h.last<mv::MissionRequest>(from)->seq, 1);

    auto bad = to_float(waypoint(home, 20, 0));
    bad.seq = 1;
    bad.frame = 1;  // MAV_FRAME_LOCAL_NED
    from = h.received.size();
    h.send(bad);
    ASSERT_TRUE(h.last<mv::MissionAck>(from));
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 2) << "MAV_MISSION_UNSUPPORTED_FRAME";
    const auto again = h.wait_for<mv::MissionRequest>(seconds(1), from);
    ASSERT_TRUE(again) << "the board still waits for the item";
    EXPECT_EQ(again->seq, 1);
    bad.frame = 6;  // MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    from = h.received.size();
    h.send(bad);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 2);
    auto loiter = to_float(waypoint(home, 20, 0));
    loiter.seq = 1;
    loiter.command = 17;  // NAV_LOITER_UNLIM: 2.x cannot store it
    from = h.received.size();
    h.send(loiter);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 3) << "MAV_MISSION_UNSUPPORTED";

    auto good = to_float(waypoint(home, 20, 0));
    good.seq = 1;
    from = h.received.size();
    h.send(good);
    ASSERT_EQ(h.last<mv::MissionRequest>(from)->seq, 2);
    auto last = to_float(waypoint(home, 40, 0));
    last.seq = 2;
    h.send(last);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 0);
    EXPECT_EQ(h.sim.mission().at(1).command, 16);
}

TEST(ApmsimRover2, ReachedIsReportedByTextOnlyAndTheMissionEndsInHold) {
    SimHarness h(rover2());
    boot_rover2(h);
    ASSERT_EQ(h.upload_float(to_float(line_mission(h.sim.config().home, 2, 15))), 0);
    const std::size_t from = h.received.size();
    h.set_mode_message(RoverMode::Auto);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Auto);
    EXPECT_TRUE(h.all<mv::CommandAck>(from).empty()) << "2.x does not acknowledge SET_MODE";
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(60)));
    EXPECT_TRUE(h.all<mv::MissionItemReached>().empty());
    std::vector<std::string> reached;
    for (const auto& t : h.all<mv::Statustext>(from)) {
        const std::string s(mv::text_of(t.text));
        if (s.rfind("Reached Waypoint #", 0) == 0) {
            reached.push_back(s);
            EXPECT_EQ(t.severity, kSeverityLow);
        }
    }
    ASSERT_EQ(reached.size(), 2u);
    EXPECT_EQ(reached[0].rfind("Reached Waypoint #1 dist ", 0), 0u) << reached[0];
    EXPECT_EQ(reached[1].rfind("Reached Waypoint #2 dist ", 0), 0u) << reached[1];
    EXPECT_TRUE(has_text(h.texts(from), "No commands - setting HOLD"));
    EXPECT_EQ(h.sim.mode_history().back().cause, "mission end");
    h.run_for(milliseconds(1100));
    const auto hb = h.last<mv::Heartbeat>();
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->custom_mode, 4u);
    EXPECT_EQ(hb->system_status, 0) << "2.x reports HOLD with system status 0";
}

TEST(ApmsimRover2, EnteringAutoRestartsAtItemOneWhateverSetCurrentSaid) {
    SimHarness h(rover2());
    boot_rover2(h);
    const auto items = line_mission(h.sim.config().home, 3, 20);
    ASSERT_EQ(h.upload_float(to_float(items)), 0);
    h.set_mode_message(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.reached_total() == 1; }, seconds(60)));
    h.set_mode_message(RoverMode::Hold);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().speed == 0; }, seconds(10)));

    mv::MissionSetCurrent sc;
    sc.seq = 3;
    const std::size_t from = h.received.size();
    h.send(sc);
    const auto current = h.last<mv::MissionCurrent>(from);
    ASSERT_TRUE(current);
    EXPECT_EQ(current->seq, 3) << "MISSION_CURRENT reports the command index";
    EXPECT_TRUE(has_text(h.texts(from), "Received Request - jump to command #3"));
    EXPECT_EQ(h.sim.state().mode, RoverMode::Hold);

    h.set_mode_message(RoverMode::Auto);
    ASSERT_TRUE(h.sim.state().target);
    EXPECT_LT(distance_m(*h.sim.state().target, waypoint_point(items[1])), 0.5) << "restart_nav(): item 1";
    EXPECT_EQ(h.sim.state().current_seq, 1);
    ASSERT_TRUE(h.run_until([&] { return h.sim.reached_total() == 2; }, seconds(60)));
    EXPECT_EQ(h.sim.reached().back().seq, 1);
}

TEST(ApmsimRover2, SetCurrentInAutoRetargetsAtOnce) {
    SimHarness h(rover2());
    boot_rover2(h);
    const auto items = line_mission(h.sim.config().home, 3, 20);
    ASSERT_EQ(h.upload_float(to_float(items)), 0);
    h.set_mode_message(RoverMode::Auto);
    h.run_for(seconds(2));
    mv::MissionSetCurrent sc;
    sc.seq = 3;
    const std::size_t from = h.received.size();
    h.send(sc);
    EXPECT_EQ(h.last<mv::MissionCurrent>(from)->seq, 3);
    ASSERT_TRUE(h.sim.state().target);
    EXPECT_LT(distance_m(*h.sim.state().target, waypoint_point(items[3])), 0.5);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(90)));
    EXPECT_EQ(reached_seqs(h.sim), (std::vector<std::uint16_t>{3}));

    sc.seq = 2;  // a non-nav index refuses
    const std::size_t before = h.received.size();
    ASSERT_EQ(h.upload_float({to_float(waypoint(h.sim.config().home, 0, 0)),
                              to_float(waypoint(h.sim.config().home, 20, 0)), command_item(178, 0, 3)}),
              0);
    h.send(sc);
    EXPECT_TRUE(has_text(h.texts(before), "Bad Request - cannot change to non-Nav cmd"));
}

TEST(ApmsimRover2, DoJumpCountsDownInTheStoredMissionAndATrailingJumpNeverRuns) {
    SimHarness h(rover2());
    boot_rover2(h);
    const GeoPoint home = h.sim.config().home;
    std::vector<mv::MissionItem> items{to_float(waypoint(home, 0, 0)), to_float(waypoint(home, 20, 0)),
                                       to_float(waypoint(home, 40, 0)), command_item(177, 1, 1),
                                       to_float(waypoint(home, 60, 0))};
    ASSERT_EQ(h.upload_float(items), 0);
    std::size_t from = h.received.size();
    h.set_mode_message(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(200)));
    EXPECT_EQ(reached_seqs(h.sim), (std::vector<std::uint16_t>{1, 2, 1, 2, 4}));
    EXPECT_TRUE(has_text(h.texts(from), "In jump.  Jumps left: 1"));
    EXPECT_TRUE(has_text(h.texts(from), "In jump.  Jumps left: 0"));
    const auto jump = download_item(h, 3);
    ASSERT_TRUE(jump);
    EXPECT_EQ(jump->param2, 0) << "do_jump() decrements the count in EEPROM";

    // A jump with no place after it is never run: the search for the next place ends the mission first.
    items.pop_back();
    items.back().param2 = 2;
    ASSERT_EQ(h.upload_float(items), 0);
    const std::size_t reached_before = h.sim.reached().size();
    from = h.received.size();
    h.set_mode_message(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(200)));
    EXPECT_EQ(reached_seqs(h.sim, reached_before), (std::vector<std::uint16_t>{1, 2}));
    EXPECT_FALSE(has_text(h.texts(from), "In jump."));
}

TEST(ApmsimRover2, ASingleWaypointMissionNeverEnds) {
    SimHarness h(rover2());
    boot_rover2(h);
    ASSERT_EQ(h.upload_float(to_float(line_mission(h.sim.config().home, 1, 20))), 0);
    h.set_mode_message(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.reached_total() == 1; }, seconds(60)));
    const std::size_t from = h.received.size();
    h.run_for(seconds(5));
    EXPECT_EQ(h.sim.state().mode, RoverMode::Auto) << "update_commands() needs more than one item after home";
    int complaints = 0;
    for (const auto& t : h.all<mv::Statustext>(from)) {
        if (mv::text_of(t.text) == "verify_nav: Invalid or no current Nav cmd") {
            EXPECT_EQ(t.severity, kSeverityHigh);
            ++complaints;
        }
    }
    EXPECT_GE(complaints, 45) << "one every 100 ms";
}

TEST(ApmsimRover2, CommandsModesAndTargetsAsThe2xHandlersServeThem) {
    SimHarness h(rover2());
    boot_rover2(h);
    EXPECT_EQ(h.last<mv::Heartbeat>()->custom_mode, 0u) << "MANUAL after boot";
    std::size_t from = h.received.size();
    auto ack = command(h, 176, 1, 4);  // DO_SET_MODE as modern stations send it (custom mode in param2)
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->result, 3) << "2.x matches param1 against MAV_MODE values only";
    EXPECT_EQ(h.sim.state().mode, RoverMode::Manual);
    EXPECT_TRUE(has_text(h.texts(from), "command received: "));
    EXPECT_EQ(command(h, 178, 1, 4)->result, 3) << "no DO_CHANGE_SPEED command";
    EXPECT_EQ(command(h, 400, 1)->result, 3) << "no arming command";
    EXPECT_EQ(command(h, 520, 1)->result, 3) << "no AUTOPILOT_VERSION";

    // Broadcast (target 0) is not for a 2.x board.
    mv::CommandLong broadcast;
    broadcast.command = 20;
    mv::Encoder raw(255, 190, mv::Version::V1);
    from = h.received.size();
    h.sim.handle_bytes(raw.encode(broadcast), h.now);
    h.run_for(milliseconds(10));
    EXPECT_FALSE(h.last<mv::CommandAck>(from));
    EXPECT_EQ(h.sim.state().mode, RoverMode::Manual);

    for (const RoverMode m : {RoverMode::Learning, RoverMode::Steering, RoverMode::Hold}) {
        h.set_mode_message(m);
        EXPECT_EQ(h.sim.state().mode, m);
        h.run_for(milliseconds(1000));
        EXPECT_EQ(h.last<mv::Heartbeat>()->custom_mode, static_cast<std::uint32_t>(m));
    }
    h.set_mode_message(RoverMode::Guided);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Hold) << "SET_MODE does not take GUIDED on 2.x";

    // MAV_MODE_AUTO_ARMED without a mission: AUTO, then "No commands - setting HOLD" at once.
    from = h.received.size();
    EXPECT_EQ(command(h, 176, 220)->result, 0);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Hold);
    const auto& hist = h.sim.mode_history();
    ASSERT_GE(hist.size(), 2u);
    EXPECT_EQ(hist[hist.size() - 2].to, RoverMode::Auto);
    EXPECT_EQ(hist.back().cause, "mission end");
    EXPECT_TRUE(has_text(h.texts(from), "No commands - setting HOLD"));

    EXPECT_FALSE(h.sim.force_mode(RoverMode::Acro, h.now)) << "2.x has no ACRO";
    EXPECT_FALSE(h.sim.force_mode(RoverMode::Loiter, h.now));
    EXPECT_TRUE(h.sim.force_mode(RoverMode::Manual, h.now));
    EXPECT_EQ(h.sim.mode_history().back().cause, "board");

    from = h.received.size();
    EXPECT_FALSE(command(h, 246, 1)) << "reboot_apm() does not return: no COMMAND_ACK";
    EXPECT_EQ(h.sim.state().boots, 2u);
}

TEST(ApmsimRover2, GuidedGoToDrivesThereInRtlAndHolds) {
    SimHarness h(rover2());
    boot_rover2(h);
    auto go = to_float(waypoint(h.sim.config().home, 0, 30));
    go.current = 2;
    const std::size_t from = h.received.size();
    h.send(go);
    ASSERT_TRUE(h.last<mv::MissionAck>(from));
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 0) << "accepted in any mode";
    EXPECT_EQ(h.sim.state().mode, RoverMode::Rtl) << "set_mode(GUIDED) ends in do_RTL() before 2.50";
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(60)));
    EXPECT_TRUE(has_text(h.texts(from), "Reached home"));
    EXPECT_LT(distance_m(h.sim.state().position, GeoPoint{go.x, go.y}), 3.0) << "at the point, not at home";
    EXPECT_EQ(h.sim.mission().count(), 1u);
}

TEST(ApmsimRover2, OptionsAndControl) {
    const auto o = parse_options({"--link", "x", "--firmware", "rover2"});
    ASSERT_TRUE(o);
    EXPECT_EQ(o->sim.firmware, FirmwareProfile::rover2());
    EXPECT_EQ(o->sim.version, mv::Version::V1);
    EXPECT_EQ(o->sim.reached_style, ReachedStyle::TextOnly);
    EXPECT_EQ(o->sim.mission_rerequest, milliseconds(500));
    EXPECT_EQ(o->sim.mission_give_up, seconds(1));
    const auto both = parse_options({"--reached-style", "both", "--link", "x", "--firmware", "ROVER2"});
    ASSERT_TRUE(both);
    EXPECT_EQ(both->sim.reached_style, ReachedStyle::MessageAndText) << "explicit options win";
    EXPECT_EQ(parse_options({"--link", "x"})->sim.firmware, FirmwareProfile::modern());
    EXPECT_THROW(parse_options({"--link", "x", "--firmware", "rover3"}), cli::UsageError);
    EXPECT_THROW(parse_options({"--link", "x", "--firmware"}), cli::UsageError);

    SimHarness h(rover2());
    boot_rover2(h);
    const LinkControl link;
    const auto state = nlohmann::json::parse(apply_control(h.sim, "state", h.now, link));
    EXPECT_EQ(state["firmware"], "rover2");
    EXPECT_EQ(apply_control(h.sim, "mode hold", h.now, link), "ok mode HOLD");
    EXPECT_EQ(h.sim.mode_history().back().cause, "board");
    EXPECT_EQ(apply_control(h.sim, "mode ACRO", h.now, link).rfind("error: mode: ACRO refused", 0), 0u);
    EXPECT_EQ(apply_control(h.sim, "mode FLY", h.now, link).rfind("error: mode: unknown mode", 0), 0u);
    const auto stats = nlohmann::json::parse(apply_control(h.sim, "stats", h.now, link));
    EXPECT_EQ(stats["mavlink2_ignored"], 0);
}

}  // namespace
}  // namespace airseg::apmsim::test
