// MissionClient against the scripted Rover over simulated links: clean, lossy, slow, and hostile peers.
#include "services/autopilot/ardupilot/mission_client.hpp"

#include <gtest/gtest.h>

#include <sstream>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/unit/autopilot/fake_rover.hpp"
#include "tests/unit/autopilot/sim_harness.hpp"

namespace airseg::autopilot::ardupilot {
namespace {

using testing::FakeRover;
using testing::Harness;
using testing::LinkModel;
using testing::Party;
namespace mav = airseg::mavlink;

const TimePoint kStart = TimePoint{} + std::chrono::hours(1);

std::vector<mav::MissionItemInt> make_items(std::size_t n) {
    std::vector<mav::MissionItemInt> items;
    for (std::size_t i = 0; i < n; ++i) {
        mav::MissionItemInt it;
        it.frame = 6;
        it.command = 16;
        it.autocontinue = 1;
        it.x = 413900000 + static_cast<std::int32_t>(i * 37);
        it.y = 21100000 - static_cast<std::int32_t>(i * 11);
        it.z = static_cast<float>(i % 7);
        it.param2 = 1.5f;
        items.push_back(it);
    }
    return items;
}

struct Ground {
    explicit Ground(MissionConfig config)
        : outbox(255, 190, mav::Version::V2), client(outbox, 1, 1, config) {}
    Outbox outbox;
    mav::Parser parser;
    MissionClient client;
    std::vector<MissionCompletion> completions;

    Party party() {
        Party p;
        p.receive = [this](std::span<const std::uint8_t> b, TimePoint now) {
            parser.push(b, [&](const mav::Frame& f) { client.handle_frame(f, now); });
            drain();
        };
        p.transmit = [this] { return outbox.poll_transmit(); };
        p.on_timeout = [this](TimePoint now) {
            client.handle_timeout(now);
            drain();
        };
        p.deadline = [this] { return client.poll_timeout(); };
        return p;
    }
    void drain() {
        while (auto c = client.poll_completion()) {
            completions.push_back(std::move(*c));
        }
    }
};

Party vehicle_party(FakeRover& rover) {
    Party p;
    p.receive = [&rover](std::span<const std::uint8_t> b, TimePoint now) { rover.handle_bytes(b, now); };
    p.transmit = [&rover] { return rover.poll_transmit(); };
    p.on_timeout = [&rover](TimePoint now) { rover.handle_timeout(now); };
    p.deadline = [&rover] { return rover.poll_timeout(); };
    return p;
}

struct Fixture {
    Fixture(LinkModel link, std::uint32_t seed, FakeRover::Options opts = {}, MissionConfig config = {})
        : ground(config),
          rover(opts, kStart),
          harness(ground.party(), vehicle_party(rover), link, link, seed, kStart) {}
    bool run_until_done(std::size_t n, Duration limit = seconds(600)) {
        return harness.run_until([&] { return ground.completions.size() >= n; }, harness.now() + limit);
    }
    Ground ground;
    FakeRover rover;
    Harness harness;
};

// Items as the vehicle stores them (slot 0 is home), for comparison with what was sent.
void expect_same_items(const std::vector<mav::MissionItemInt>& sent,
                       const std::vector<mav::MissionItemInt>& got, std::size_t first) {
    ASSERT_GE(got.size(), first + sent.size());
    for (std::size_t i = 0; i < sent.size(); ++i) {
        const auto& a = sent[i];
        const auto& b = got[first + i];
        EXPECT_EQ(a.x, b.x) << "slot " << first + i;
        EXPECT_EQ(a.y, b.y) << "slot " << first + i;
        EXPECT_EQ(a.z, b.z) << "slot " << first + i;
        EXPECT_EQ(a.command, b.command) << "slot " << first + i;
        EXPECT_EQ(a.param2, b.param2) << "slot " << first + i;
    }
}

TEST(MissionClient, UploadThenDownloadOnACleanLink) {
    Fixture fx({}, 1);
    auto items = make_items(20);
    items.insert(items.begin(), fx.rover.mission()[0]);  // keep home in slot 0
    const auto up = fx.ground.client.upload(items, fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(1));
    EXPECT_EQ(fx.ground.completions[0].id, up);
    EXPECT_EQ(fx.ground.completions[0].result, MissionResult::Success) << fx.ground.completions[0].detail;
    ASSERT_EQ(fx.rover.mission().size(), 21u);

    fx.ground.client.download(fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(2));
    const auto& down = fx.ground.completions[1];
    EXPECT_EQ(down.operation, MissionOperation::Download);
    ASSERT_EQ(down.result, MissionResult::Success) << down.detail;
    expect_same_items(items, down.items, 0);
    EXPECT_EQ(fx.ground.client.stats().retransmissions, 0u);
    ASSERT_TRUE(fx.ground.client.smoothed_rtt().has_value());
}

TEST(MissionClient, Upload150ItemsWithTenPercentFramesLostBothWaysVerifiedByDownload) {
    LinkModel radio;
    radio.baud = 57600;
    radio.latency = milliseconds(30);
    radio.frame_drop = 0.10;
    Fixture fx(radio, 42, {.max_items = 400});
    auto items = make_items(150);
    fx.ground.client.upload(items, fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(1));
    ASSERT_EQ(fx.ground.completions[0].result, MissionResult::Success) << fx.ground.completions[0].detail;
    EXPECT_GT(fx.ground.client.stats().retransmissions + fx.ground.client.stats().duplicate_requests, 0u);
    EXPECT_GT(fx.harness.to_vehicle().dropped_frames(), 0u);

    fx.ground.client.download(fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(2));
    ASSERT_EQ(fx.ground.completions[1].result, MissionResult::Success) << fx.ground.completions[1].detail;
    expect_same_items(items, fx.ground.completions[1].items, 0);
    expect_same_items(items, fx.rover.mission(), 0);
}

TEST(MissionClient, SurvivesByteLevelCorruption) {
    LinkModel noisy;
    noisy.baud = 57600;
    noisy.byte_drop = 0.002;
    Fixture fx(noisy, 7);
    auto items = make_items(60);
    fx.ground.client.upload(items, fx.harness.now());
    fx.ground.client.download(fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(2));
    ASSERT_EQ(fx.ground.completions[0].result, MissionResult::Success) << fx.ground.completions[0].detail;
    ASSERT_EQ(fx.ground.completions[1].result, MissionResult::Success) << fx.ground.completions[1].detail;
    expect_same_items(items, fx.ground.completions[1].items, 0);
}

TEST(MissionClient, TimeoutAdaptsToASlowLinkInsteadOfFailing) {
    // 150 ms each way: a fixed 0.5 s timeout would retransmit constantly; the adapted one settles above the
    // RTT.
    LinkModel slow;
    slow.baud = 57600;
    slow.latency = milliseconds(300);
    MissionConfig config;
    config.initial_timeout = milliseconds(500);
    config.min_timeout = milliseconds(200);
    Fixture fx(slow, 3, {}, config);
    fx.ground.client.upload(make_items(30), fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(1));
    ASSERT_EQ(fx.ground.completions[0].result, MissionResult::Success) << fx.ground.completions[0].detail;
    ASSERT_TRUE(fx.ground.client.smoothed_rtt());
    EXPECT_GT(*fx.ground.client.smoothed_rtt(), milliseconds(600));
    EXPECT_GT(fx.ground.client.base_timeout(), *fx.ground.client.smoothed_rtt());
    // Only the first exchange (before any RTT sample) may have been retransmitted.
    EXPECT_LE(fx.ground.client.stats().retransmissions, 2u);
}

TEST(MissionClient, AnswersMissionRequestWithFloatItemsWithoutUseInt) {
    MissionConfig config;
    config.use_int = false;
    Fixture fx({}, 5, {.request_int = false}, config);
    auto items = make_items(5);
    fx.ground.client.upload(items, fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(1));
    ASSERT_EQ(fx.ground.completions[0].result, MissionResult::Success);
    // The float path rounds through degrees as float: within 1e-7 degree * float precision.
    for (std::size_t i = 0; i < items.size(); ++i) {
        EXPECT_NEAR(fx.rover.mission()[i].x, items[i].x, 20);
        EXPECT_NEAR(fx.rover.mission()[i].y, items[i].y, 20);
    }
}

TEST(MissionClient, AnswersMissionRequestWithIntItemsWithUseInt) {
    Fixture fx({}, 5, {.request_int = false});
    auto items = make_items(5);
    items[3].x = 412756789;  // needs more digits than a float carries
    fx.ground.client.upload(items, fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(1));
    ASSERT_EQ(fx.ground.completions[0].result, MissionResult::Success);
    EXPECT_EQ(fx.rover.mission()[3].x, 412756789);
}

TEST(MissionClient, PartialWriteReplacesOnlyItsSlots) {
    Fixture fx({}, 9);
    auto items = make_items(8);
    fx.ground.client.upload(items, fx.harness.now());
    auto patch = make_items(2);
    patch[0].x = 1;
    patch[1].x = 2;
    fx.ground.client.write_partial(3, patch, fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(2));
    ASSERT_EQ(fx.ground.completions[1].operation, MissionOperation::WritePartial);
    ASSERT_EQ(fx.ground.completions[1].result, MissionResult::Success) << fx.ground.completions[1].detail;
    EXPECT_EQ(fx.rover.mission()[3].x, 1);
    EXPECT_EQ(fx.rover.mission()[4].x, 2);
    EXPECT_EQ(fx.rover.mission()[2].x, items[2].x);
    EXPECT_EQ(fx.rover.mission()[5].x, items[5].x);
    EXPECT_EQ(fx.rover.mission().size(), 8u);
}

TEST(MissionClient, PartialWriteBeyondTheMissionIsDenied) {
    Fixture fx({}, 9);
    fx.ground.client.write_partial(10, make_items(2), fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(1));
    EXPECT_EQ(fx.ground.completions[0].result, MissionResult::Denied);
    EXPECT_NE(fx.ground.completions[0].detail.find("MAV_MISSION_ERROR"), std::string::npos);
}

// A slow link makes the vehicle ask for an item again before the first answer has reached it. The
// repeated answer then reaches a vehicle that has finished the transfer, and ArduPilot answers an item it
// does not expect with MAV_MISSION_ERROR. That error belongs to the finished transfer, not to the next
// one, which must not take it as the vehicle's verdict on its own request.
TEST(MissionClient, AnErrorAnsweringARepeatedItemDoesNotRefuseTheNextTransfer) {
    LinkModel radio;
    radio.latency = milliseconds(600);  // a round trip longer than the vehicle's 1 s re-request
    Fixture fx(radio, 5);
    fx.ground.client.upload(make_items(8), fx.harness.now());
    std::vector<std::vector<mav::MissionItemInt>> patches;
    for (int i = 0; i < 4; ++i) {
        patches.push_back(make_items(1));
        patches.back()[0].x = 100 + i;
        fx.ground.client.write_partial(static_cast<std::uint16_t>(2 + i), patches.back(), fx.harness.now());
    }
    ASSERT_TRUE(fx.run_until_done(5));
    for (const auto& c : fx.ground.completions) {
        EXPECT_EQ(c.result, MissionResult::Success) << c.detail;
    }
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(fx.rover.mission()[static_cast<std::size_t>(2 + i)].x, 100 + i);
    }
    EXPECT_GT(fx.ground.client.stats().duplicate_requests, 0u)
        << "the link did not provoke repeated requests";
    EXPECT_GT(fx.ground.client.stats().stray_errors, 0u) << "no error answered a repeated item";

    // The vehicle's own verdict still counts when it follows a stray error.
    fx.ground.client.write_partial(2, make_items(1), fx.harness.now());
    fx.ground.client.write_partial(40, make_items(1), fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(7));
    EXPECT_EQ(fx.ground.completions[5].result, MissionResult::Success) << fx.ground.completions[5].detail;
    EXPECT_EQ(fx.ground.completions[6].result, MissionResult::Denied);
    EXPECT_NE(fx.ground.completions[6].detail.find("MAV_MISSION_ERROR"), std::string::npos);
}

// Items still on the link when it went down reach a vehicle that has ended their transfer, and its ERRORs
// can arrive just after the next window write went out, before that write's first request, with no repeat
// outstanding to blame. They are not the vehicle's verdict on the write: it goes on and lands.
TEST(MissionClient, ErrorsBeforeTheFirstRequestThatAreNotRepeatedDoNotRefuseTheWrite) {
    LinkModel radio;
    radio.latency = milliseconds(100);
    Fixture fx(radio, 11);
    auto items = make_items(8);
    items.insert(items.begin(), fx.rover.mission()[0]);
    fx.ground.client.upload(items, fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(1));
    ASSERT_EQ(fx.ground.completions[0].result, MissionResult::Success) << fx.ground.completions[0].detail;

    auto patch = make_items(2);
    patch[0].x = 777;
    fx.ground.client.write_partial(3, patch, fx.harness.now());
    // Two ERRORs from the vehicle, as after an outage, read before the write's first request.
    Outbox vehicle(1, 1, mav::Version::V2);
    mav::MissionAck stray;
    stray.target_system = 255;
    stray.target_component = 190;
    stray.type = mav::kMissionError;
    vehicle.send(stray);
    vehicle.send(stray);
    auto receive = fx.ground.party().receive;
    while (auto bytes = vehicle.poll_transmit()) {
        receive(*bytes, fx.harness.now());
    }
    ASSERT_TRUE(fx.run_until_done(2));
    EXPECT_EQ(fx.ground.completions[1].result, MissionResult::Success) << fx.ground.completions[1].detail;
    EXPECT_EQ(fx.rover.mission()[3].x, 777);
    EXPECT_EQ(fx.ground.client.stats().unconfirmed_errors, 2u);

    // A vehicle that refuses the write says so again to the repeated request: that is final.
    fx.ground.client.write_partial(40, make_items(1), fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(3));
    EXPECT_EQ(fx.ground.completions[2].result, MissionResult::Denied);
    EXPECT_NE(fx.ground.completions[2].detail.find("MAV_MISSION_ERROR"), std::string::npos);
}

TEST(MissionClient, SetCurrentIsConfirmedByMissionCurrent) {
    Fixture fx({.frame_drop = 0.3}, 11);
    fx.ground.client.upload(make_items(6), fx.harness.now());
    fx.ground.client.set_current(4, fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(2));
    ASSERT_EQ(fx.ground.completions[1].result, MissionResult::Success) << fx.ground.completions[1].detail;
    EXPECT_EQ(fx.rover.mission_current(), 4);
}

TEST(MissionClient, ClearAll) {
    Fixture fx({}, 12);
    fx.ground.client.upload(make_items(6), fx.harness.now());
    fx.ground.client.clear(fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(2));
    EXPECT_EQ(fx.ground.completions[1].result, MissionResult::Success);
    EXPECT_EQ(fx.rover.mission().size(), 1u);
}

TEST(MissionClient, NoSpaceIsReportedAsSuch) {
    Fixture fx({}, 13, {.max_items = 10});
    fx.ground.client.upload(make_items(11), fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(1));
    EXPECT_EQ(fx.ground.completions[0].result, MissionResult::NoSpace);
}

TEST(MissionClient, SilentVehicleTimesOutAfterTheRetryBudget) {
    MissionConfig config;
    config.retries = 3;
    Fixture fx({}, 14, {}, config);
    fx.rover.stall(kStart + std::chrono::hours(1));
    fx.ground.client.upload(make_items(3), fx.harness.now());
    ASSERT_TRUE(fx.run_until_done(1, seconds(120)));
    EXPECT_EQ(fx.ground.completions[0].result, MissionResult::Timeout);
    EXPECT_EQ(fx.ground.client.stats().retransmissions, 3u);
    EXPECT_NE(fx.ground.completions[0].detail.find("first item request"), std::string::npos);
    std::ostringstream os;
    os << fx.ground.completions[0].result;
    EXPECT_EQ(os.str(), "timeout");
}

TEST(MissionClient, InvalidArgumentsAreRefusedBeforeSending) {
    MissionConfig config;
    config.max_items = 10;
    Outbox out(255, 190, mav::Version::V2);
    MissionClient client(out, 1, 1, config);
    client.upload(make_items(11), kStart);
    client.write_partial(1, {}, kStart);
    auto a = client.poll_completion();
    auto b = client.poll_completion();
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->result, MissionResult::InvalidArgument);
    EXPECT_EQ(b->result, MissionResult::InvalidArgument);
    EXPECT_TRUE(out.empty());
    EXPECT_TRUE(client.idle());
}

TEST(MissionClient, CancelAllEndsEveryOperationOnce) {
    Outbox out(255, 190, mav::Version::V2);
    MissionClient client(out, 1, 1, {});
    client.upload(make_items(3), kStart);
    client.download(kStart);
    client.cancel_all("link down");
    std::vector<MissionCompletion> cs;
    while (auto c = client.poll_completion()) {
        cs.push_back(*c);
    }
    ASSERT_EQ(cs.size(), 2u);
    EXPECT_EQ(cs[0].result, MissionResult::Cancelled);
    EXPECT_EQ(cs[1].result, MissionResult::Cancelled);
    EXPECT_EQ(client.poll_timeout(), kNever);
}

/// airsegd's mission client (system 255) next to a ground station with another system id, both talking to
/// the autopilot (system 1) through the same port.
struct SharedPort {
    Outbox out{255, 190, mav::Version::V2};
    MissionClient client{out, 1, 1, {}};
    mav::Encoder vehicle{1, 1};
    mav::Parser parser;

    template <class M>
    void from_vehicle(const M& m) {
        parser.push(vehicle.encode(m), [&](const mav::Frame& f) { client.handle_frame(f, kStart); });
    }
};

TEST(MissionClient, IgnoresAnotherGroundStationsTransfer) {
    SharedPort port;
    port.client.upload(make_items(3), kStart);
    (void)port.out.poll_transmit();
    // A request addressed to sysid 254 must not make us send an item.
    mav::MissionRequestInt r;
    r.target_system = 254;
    r.seq = 0;
    port.from_vehicle(r);
    EXPECT_TRUE(port.out.empty());
}

TEST(MissionClient, ADownloadIgnoresAnswersToAnotherGroundStation) {
    // A ground station (system 254) downloads the mission through airsegd while airsegd downloads it too:
    // the autopilot's answers to the ground station must not be taken for ours.
    SharedPort port;
    port.client.download(kStart);
    (void)port.out.poll_transmit();
    mav::MissionCount count;
    count.target_system = 254;
    count.count = 7;
    mav::MissionItemInt item;
    item.target_system = 254;
    port.from_vehicle(count);
    port.from_vehicle(item);
    EXPECT_TRUE(port.out.empty());  // no MISSION_REQUEST_INT for the other station's items
    EXPECT_FALSE(port.client.poll_completion());
    // Our own answer still works.
    count.target_system = 255;
    count.count = 0;
    port.from_vehicle(count);
    const auto done = port.client.poll_completion();
    ASSERT_TRUE(done);
    EXPECT_EQ(done->result, MissionResult::Success);
}

TEST(MissionClient, IgnoresAnswersToAGroundStationOnTheSameSystemId) {
    // QGroundControl's default identity (255/190) next to airsegd's (255/191): the autopilot answers each
    // requester's system and component, so only the component tells the answers apart.
    Outbox out{255, 191, mav::Version::V2};
    MissionClient client{out, 1, 1, {}};
    mav::Encoder vehicle{1, 1};
    mav::Parser parser;
    auto from_vehicle = [&](const auto& m) {
        parser.push(vehicle.encode(m), [&](const mav::Frame& f) { client.handle_frame(f, kStart); });
    };
    client.download(kStart);
    (void)out.poll_transmit();
    mav::MissionCount count;
    count.target_system = 255;
    count.target_component = 190;
    count.count = 7;
    from_vehicle(count);
    EXPECT_TRUE(out.empty());
    EXPECT_FALSE(client.poll_completion());
    count.target_component = 191;
    count.count = 0;
    from_vehicle(count);
    const auto done = client.poll_completion();
    ASSERT_TRUE(done);
    EXPECT_EQ(done->result, MissionResult::Success);
    // Component 0 is anyone's: boards that fill in the system only still reach us.
    client.download(kStart);
    (void)out.poll_transmit();
    count.target_component = 0;
    from_vehicle(count);
    ASSERT_TRUE(client.poll_completion());
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot
