// RoverSim's mission protocol server in simulated time: the edge cases a mission client must survive.
#include <gtest/gtest.h>

#include "tests/integration/apmsim/sim_harness.hpp"

namespace airseg::apmsim::test {
namespace {

constexpr std::uint8_t kAccepted = 0;
constexpr std::uint8_t kError = 1;
constexpr std::uint8_t kNoSpace = 4;
constexpr std::uint8_t kInvalidSequence = 13;
constexpr std::uint8_t kDenied = 14;
constexpr std::uint8_t kCancelled = 15;

class ApmsimMission : public ::testing::Test {
  protected:
    void SetUp() override { h.boot(); }
    RoverSimConfig config() {
        RoverSimConfig c;
        c.mission_capacity = 20;
        return c;
    }
    SimHarness h{config()};
};

TEST_F(ApmsimMission, UploadThenDownloadRoundTrip) {
    const auto items = line_mission(h.sim.config().home, 5, 10);
    ASSERT_EQ(h.upload(items), kAccepted);
    EXPECT_EQ(h.sim.mission().count(), 6u);
    EXPECT_TRUE(h.wait_text("flight plan received", seconds(1)) || h.all<mv::Statustext>().size() > 0);

    std::size_t from = h.received.size();
    h.send(mv::MissionRequestList{});
    auto count = h.last<mv::MissionCount>(from);
    ASSERT_TRUE(count);
    EXPECT_EQ(count->count, 6);
    EXPECT_EQ(count->target_system, 255);
    for (std::uint16_t seq = 0; seq < 6; ++seq) {
        mv::MissionRequestInt r;
        r.seq = seq;
        from = h.received.size();
        h.send(r);
        auto item = h.last<mv::MissionItemInt>(from);
        ASSERT_TRUE(item) << seq;
        EXPECT_EQ(item->seq, seq);
        if (seq > 0) {
            EXPECT_EQ(item->x, items[seq].x);
            EXPECT_EQ(item->y, items[seq].y);
            EXPECT_EQ(item->command, 16);
        }
    }
    // Item 0 is the board's home, whatever was uploaded there; MISSION_REQUEST gets float MISSION_ITEM.
    mv::MissionRequest r0;
    r0.seq = 0;
    from = h.received.size();
    h.send(r0);
    auto home = h.last<mv::MissionItem>(from);
    ASSERT_TRUE(home);
    EXPECT_NEAR(home->x, h.sim.config().home.lat, 1e-5);
    EXPECT_NEAR(home->y, h.sim.config().home.lon, 1e-5);
}

TEST_F(ApmsimMission, NoSpaceBeyondCapacity) {
    mv::MissionCount c;
    c.count = 21;
    const std::size_t from = h.received.size();
    h.send(c);
    auto ack = h.last<mv::MissionAck>(from);
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->type, kNoSpace);
    EXPECT_TRUE(h.all<mv::MissionRequest>(from).empty());
    EXPECT_EQ(h.upload(line_mission(h.sim.config().home, 19, 5)), kAccepted) << "exactly the capacity fits";
}

TEST_F(ApmsimMission, RerequestsAfterOneSecondAndCancelsAfterEight) {
    mv::MissionCount c;
    c.count = 3;
    const std::size_t from = h.received.size();
    h.send(c);
    const TimePoint sent = h.now;
    ASSERT_EQ(h.all<mv::MissionRequest>(from).size(), 1u);
    h.run_until_time(sent + milliseconds(990));
    EXPECT_EQ(h.all<mv::MissionRequest>(from).size(), 1u) << "no re-request before 1 s";
    h.run_until_time(sent + milliseconds(1010));
    const auto again = h.all<mv::MissionRequest>(from);
    ASSERT_EQ(again.size(), 2u);
    EXPECT_EQ(again[1].seq, 0);

    auto ack = h.wait_for<mv::MissionAck>(seconds(10), from);
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->type, kCancelled);
    const auto at = std::find_if(h.received.begin() + static_cast<std::ptrdiff_t>(from), h.received.end(),
                                 [](const Received& r) { return r.frame.msgid == mv::MissionAck::kId; })
                        ->at;
    EXPECT_GE(at - sent, seconds(8));
    EXPECT_LT(at - sent, seconds(9));
    EXPECT_EQ(h.sim.mission_stats().uploads_cancelled, 1u);
    // Progress refreshes the 8 s: an upload answered every 5 s is not cancelled.
}

TEST_F(ApmsimMission, SlowButSteadyUploadIsNotCancelled) {
    const auto items = line_mission(h.sim.config().home, 3, 10);
    mv::MissionCount c;
    c.count = 4;
    h.send(c);
    for (std::uint16_t seq = 0; seq < 4; ++seq) {
        h.run_for(seconds(5));
        auto item = items[seq];
        item.seq = seq;
        h.send(item);
    }
    auto ack = h.last<mv::MissionAck>();
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->type, kAccepted);
    EXPECT_GE(h.sim.mission_stats().rerequests, 4u);
}

TEST_F(ApmsimMission, SecondUploaderRefused) {
    mv::Encoder other(254, 190);
    mv::MissionCount c;
    c.count = 3;
    h.send(c);
    std::size_t from = h.received.size();
    h.send(c, &other);
    auto ack = h.last<mv::MissionAck>(from);
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->type, kDenied);
    EXPECT_EQ(ack->target_system, 254);
    from = h.received.size();
    h.send(mv::MissionRequestList{}, &other);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, kDenied) << "no download during an upload either";
    // The first uploader carries on.
    EXPECT_EQ(h.upload(line_mission(h.sim.config().home, 2, 10)), kAccepted);
}

TEST_F(ApmsimMission, OutOfOrderItemGetsInvalidSequence) {
    const auto items = line_mission(h.sim.config().home, 2, 10);
    mv::MissionCount c;
    c.count = 3;
    h.send(c);
    auto wrong = items[2];
    wrong.seq = 2;
    std::size_t from = h.received.size();
    h.send(wrong);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, kInvalidSequence);
    EXPECT_TRUE(h.sim.mission_stats().items_received == 0);
}

TEST_F(ApmsimMission, PartialWriteReplacesAndAppends) {
    const auto items = line_mission(h.sim.config().home, 4, 10);
    ASSERT_EQ(h.upload(items), kAccepted);
    mv::MissionWritePartialList p;
    p.start_index = 2;
    p.end_index = 2;
    std::size_t from = h.received.size();
    h.send(p);
    auto req = h.last<mv::MissionRequest>(from);
    ASSERT_TRUE(req);
    EXPECT_EQ(req->seq, 2);
    auto replacement = waypoint(h.sim.config().home, 0, 50);
    replacement.seq = 2;
    from = h.received.size();
    h.send(replacement);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, kAccepted);
    EXPECT_EQ(h.sim.mission().count(), 5u);
    EXPECT_EQ(h.sim.mission().at(2).lon_e7, replacement.y);
    EXPECT_EQ(h.sim.mission().at(3).lat_e7, items[3].x) << "the rest stays";

    // start == count appends one item.
    p.start_index = 5;
    p.end_index = 5;
    h.send(p);
    auto appended = waypoint(h.sim.config().home, 60, 0);
    appended.seq = 5;
    h.send(appended);
    EXPECT_EQ(h.sim.mission().count(), 6u);

    p.start_index = 3;
    p.end_index = 9;
    from = h.received.size();
    h.send(p);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, kError) << "past the end";
}

TEST_F(ApmsimMission, ClearAllKeepsHomeButNotWhileRunning) {
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 3, 30)), kAccepted);
    h.set_mode(RoverMode::Auto);
    std::size_t from = h.received.size();
    h.send(mv::MissionClearAll{});
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, kError) << "AP_Mission refuses to clear a running mission";
    h.set_mode(RoverMode::Hold);
    from = h.received.size();
    h.send(mv::MissionClearAll{});
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, kAccepted);
    EXPECT_EQ(h.sim.mission().count(), 1u);
}

TEST_F(ApmsimMission, IgnoreMissionFaultAndSlowAnswers) {
    h.sim.faults().ignore_mission = true;
    std::size_t from = h.received.size();
    h.send(mv::MissionRequestList{});
    h.run_for(seconds(2));
    EXPECT_TRUE(h.all<mv::MissionCount>(from).empty());
    h.sim.faults().ignore_mission = false;
    h.sim.faults().slow = milliseconds(300);
    from = h.received.size();
    const TimePoint asked = h.now;
    h.send(mv::MissionRequestList{});
    EXPECT_TRUE(h.all<mv::MissionCount>(from).empty());
    ASSERT_TRUE(h.wait_for<mv::MissionCount>(seconds(1), from));
    const auto it = std::find_if(h.received.begin() + static_cast<std::ptrdiff_t>(from), h.received.end(),
                                 [](const Received& r) { return r.frame.msgid == mv::MissionCount::kId; });
    EXPECT_GE(it->at - asked, milliseconds(300));
}

TEST_F(ApmsimMission, MissionSurvivesReboot) {
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 7, 10)), kAccepted);
    h.sim.reboot(h.now);
    h.boot();
    EXPECT_EQ(h.sim.mission().count(), 8u);
    EXPECT_EQ(h.sim.state().current_seq, 0);
}

}  // namespace
}  // namespace airseg::apmsim::test

namespace airseg::apmsim::test {
namespace {

TEST(ApmsimMissionTypes, FenceAndRallyAreUnsupported) {
    SimHarness h;
    h.boot();
    mv::MissionRequestList list;
    list.mission_type = 1;  // MAV_MISSION_TYPE_FENCE
    std::size_t from = h.received.size();
    h.send(list);
    EXPECT_FALSE(h.last<mv::MissionCount>(from));
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 3);
    mv::MissionCount count;
    count.count = 4;
    count.mission_type = 2;  // MAV_MISSION_TYPE_RALLY
    from = h.received.size();
    h.send(count);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 3);
    EXPECT_FALSE(h.sim.mission_stats().uploads_completed);
}

}  // namespace
}  // namespace airseg::apmsim::test
