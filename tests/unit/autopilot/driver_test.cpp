// The ArduPilot driver core against the scripted Rover, in simulated time: connection sequence, vehicle
// states, pilot mode changes, RC override, reboots, stalls, reset pulses, baud probing, missions.
#include "services/autopilot/ardupilot/driver.hpp"

#include <gtest/gtest.h>

#include "services/autopilot/mavlink/enums.hpp"
#include "tests/unit/autopilot/fake_rover.hpp"
#include "tests/unit/autopilot/sim_harness.hpp"

namespace airseg::autopilot::ardupilot {
namespace {

using testing::FakeRover;
using testing::Harness;
using testing::LinkModel;
using testing::Party;
namespace mav = airseg::mavlink;

const TimePoint kDriverTestStart = TimePoint{} + std::chrono::hours(2);

AutopilotConfig apm2_config() {
    auto c = AutopilotConfig::defaults_for(Board::Apm2);
    c.params = {{"CRUISE_SPEED", 3.0}, {"WP_RADIUS", 2.0}};
    return c;
}

struct Rig {
    Rig(AutopilotConfig config, FakeRover::Options opts, LinkModel link = {}, std::uint32_t seed = 1)
        : driver(std::move(config)),
          rover(opts, kDriverTestStart),
          harness(ground(), vehicle(), link, link, seed, kDriverTestStart) {}

    Party ground() {
        Party p;
        p.receive = [this](std::span<const std::uint8_t> b, TimePoint now) {
            driver.handle_bytes(b, now);
            drain();
        };
        p.transmit = [this] { return driver.poll_transmit(); };
        p.on_timeout = [this](TimePoint now) {
            driver.handle_timeout(now);
            drain();
        };
        p.deadline = [this] { return driver.poll_timeout(); };
        return p;
    }
    Party vehicle() {
        Party p;
        p.receive = [this](std::span<const std::uint8_t> b, TimePoint now) { rover.handle_bytes(b, now); };
        p.transmit = [this] { return rover.poll_transmit(); };
        p.on_timeout = [this](TimePoint now) { rover.handle_timeout(now); };
        p.deadline = [this] { return rover.poll_timeout(); };
        return p;
    }
    void drain() {
        while (auto e = driver.poll_event()) {
            events.push_back(std::move(*e));
        }
        while (auto a = driver.poll_action()) {
            actions.push_back(*a);
        }
    }
    /// The open of an APM on USB resets it.
    void open_with_reset() {
        rover.reboot(now());
        driver.on_port_open(now());
        drain();
    }
    TimePoint now() const { return harness.now(); }

    template <class E>
    std::vector<E> all() const {
        std::vector<E> out;
        for (const auto& e : events) {
            if (const auto* x = std::get_if<E>(&e)) {
                out.push_back(*x);
            }
        }
        return out;
    }
    template <class E>
    bool run_until_event(std::size_t count, Duration limit) {
        return harness.run_until([&] { return all<E>().size() >= count; }, now() + limit);
    }
    std::optional<RequestDone> result_of(std::uint32_t id) const {
        for (const auto& d : all<RequestDone>()) {
            if (d.id == id) {
                return d;
            }
        }
        return std::nullopt;
    }
    RequestDone wait_result(std::uint32_t id, Duration limit = seconds(60)) {
        harness.run_until([&] { return result_of(id).has_value(); }, now() + limit);
        auto r = result_of(id);
        return r ? *r : RequestDone{id,
                                    RequestKind::SetState,
                                    RequestResult::Cancelled,
                                    "no result in time",
                                    {},
                                    {},
                                    {},
                                    {},
                                    {}};
    }
    void bring_up() {
        open_with_reset();
        ASSERT_TRUE(run_until_event<Ready>(1, seconds(40)));
    }

    Driver driver;
    FakeRover rover;
    Harness harness;
    std::vector<Event> events;
    std::vector<DriverAction> actions;
};

FakeRover::Options apm2_rover() {
    FakeRover::Options o;
    o.version = mav::Version::V1;
    o.request_int = false;
    o.send_item_reached = false;  // ArduRover 2.x announces reached waypoints only as text
    return o;
}

TEST(Driver, ReadyWithinBootDelayCalibrationAndOneSecond) {
    Rig rig(apm2_config(), apm2_rover());
    rig.open_with_reset();
    const TimePoint opened = rig.now();
    ASSERT_TRUE(rig.run_until_event<Ready>(1, seconds(40))) << rig.driver.last_error();
    const double took = std::chrono::duration<double>(rig.now() - opened).count();
    EXPECT_LE(took, 2.0 + 1.0 + 1.0);
    EXPECT_GE(took, 3.0);  // not before the autopilot finished calibrating
    EXPECT_TRUE(rig.driver.ready());
    ASSERT_TRUE(rig.driver.status().ready_s);
    EXPECT_NEAR(*rig.driver.status().ready_s, took, 1e-6);
    // Configured parameters written and verified; the one already right was not written.
    EXPECT_FLOAT_EQ(rig.rover.params()["CRUISE_SPEED"], 3.0f);
    EXPECT_EQ(rig.rover.param_sets(), 1u);
    EXPECT_EQ(rig.driver.params().table().size(), rig.rover.params().size());
    ASSERT_TRUE(rig.driver.telemetry().home);
    EXPECT_NEAR(rig.driver.telemetry().home->lat, 41.39, 1e-6);
    EXPECT_EQ(rig.driver.status().state, VehicleState::Parking);
    EXPECT_EQ(rig.driver.status().mode, "HOLD");
    // Link up was seen, and the state went through CONFIGURE_CHECK on the way.
    EXPECT_EQ(rig.all<LinkUp>().size(), 1u);
    bool saw_configure = false;
    for (const auto& m : rig.all<ModeChanged>()) {
        saw_configure = saw_configure || m.to == VehicleState::ConfigureCheck;
    }
    EXPECT_TRUE(saw_configure);
    EXPECT_EQ(rig.driver.status().reboots, 0u);
}

TEST(Driver, RequestsBeforeReadyAreRefusedAsNotReady) {
    Rig rig(apm2_config(), apm2_rover());
    rig.open_with_reset();
    const auto id = rig.driver.upload_mission({MissionItem{}}, rig.now());
    const auto st = rig.driver.request_state(VehicleState::WaypointNavigation, rig.now());
    rig.drain();
    ASSERT_TRUE(rig.result_of(id));
    EXPECT_EQ(rig.result_of(id)->result, RequestResult::NotReady);
    EXPECT_EQ(rig.result_of(st)->result, RequestResult::NotReady);
}

TEST(Driver, EachVehicleStateRequestedAndConfirmed) {
    for (const Board board : {Board::Apm2, Board::Pixhawk}) {
        SCOPED_TRACE(to_string(board));
        auto config = AutopilotConfig::defaults_for(board);
        config.bauds = {115200};
        Rig rig(config, board == Board::Apm2 ? apm2_rover() : FakeRover::Options{});
        rig.bring_up();
        struct Step {
            VehicleState state;
            std::uint32_t mode;
        };
        for (const Step s : {Step{VehicleState::WaypointNavigation, testing::kAuto},
                             Step{VehicleState::Directed, testing::kManual},
                             Step{VehicleState::ManualNavigation, testing::kManual},
                             Step{VehicleState::Parking, testing::kHold},
                             Step{VehicleState::ManualNavigation, testing::kManual},
                             Step{VehicleState::Manual, testing::kManual}}) {
            const auto r = rig.wait_result(rig.driver.request_state(s.state, rig.now()));
            EXPECT_EQ(r.result, RequestResult::Ok) << to_string(s.state) << ": " << r.detail;
            EXPECT_EQ(rig.driver.status().state, s.state);
            EXPECT_EQ(rig.rover.mode(), s.mode);
        }
        // Failsafe MANUAL holds until the operator resets it.
        const auto refused = rig.wait_result(rig.driver.request_state(VehicleState::Parking, rig.now()));
        EXPECT_EQ(refused.result, RequestResult::Refused);
        EXPECT_NE(refused.detail.find("operator reset"), std::string::npos);
        EXPECT_EQ(rig.rover.mode(), testing::kManual);
        rig.driver.operator_reset(rig.now());
        EXPECT_EQ(rig.driver.status().state, VehicleState::Directed);
        EXPECT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::Parking, rig.now())).result,
                  RequestResult::Ok);
        EXPECT_EQ(rig.rover.mode(), testing::kHold);
        // CONFIGURE_CHECK is entered by the autopilot, never on request.
        EXPECT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::ConfigureCheck, rig.now())).result,
                  RequestResult::Refused);
    }
}

TEST(Driver, RefusedModeIsReportedNotDropped) {
    auto config = AutopilotConfig::defaults_for(Board::Pixhawk);
    config.bauds = {115200};
    Rig rig(config, {});
    rig.rover.refused_modes().insert(testing::kAuto);
    rig.bring_up();
    const auto r = rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now()));
    EXPECT_EQ(r.result, RequestResult::Refused);
    EXPECT_NE(r.detail.find("MAV_RESULT_FAILED"), std::string::npos) << r.detail;
    EXPECT_EQ(rig.driver.status().state, VehicleState::Parking);
}

TEST(Driver, SilentlyIgnoredModeTimesOutAfterRetries) {
    auto config = apm2_config();
    config.mode_retries = 2;
    Rig rig(config, apm2_rover());
    rig.rover.refused_modes().insert(testing::kAuto);  // SET_MODE has no answer: only the heartbeat tells
    rig.bring_up();
    const TimePoint asked = rig.now();
    const auto r = rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now()));
    EXPECT_EQ(r.result, RequestResult::Timeout);
    EXPECT_GE(rig.now() - asked, 3 * config.mode_timeout);
    EXPECT_NE(r.detail.find("AUTO"), std::string::npos);
}

TEST(Driver, ModeChangeByThePilotIsSeen) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    const auto before = rig.all<ModeChanged>().size();
    rig.rover.pilot_sets_mode(testing::kManual, rig.now());
    rig.harness.run_for(milliseconds(100));
    const auto changes = rig.all<ModeChanged>();
    ASSERT_EQ(changes.size(), before + 1);
    EXPECT_EQ(changes.back().from, VehicleState::Parking);
    EXPECT_EQ(changes.back().to, VehicleState::Directed);
    EXPECT_EQ(changes.back().to_mode, "MANUAL");
    EXPECT_EQ(changes.back().cause, ModeChangeCause::External);
}

TEST(Driver, PilotTakingOverEndsJoystickDriving) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::ManualNavigation, rig.now())).result,
              RequestResult::Ok);
    rig.rover.pilot_sets_mode(testing::kHold, rig.now());
    rig.harness.run_for(milliseconds(100));
    rig.rover.pilot_sets_mode(testing::kManual, rig.now());
    rig.harness.run_for(milliseconds(100));
    EXPECT_EQ(rig.driver.status().state, VehicleState::Directed);
}

TEST(Driver, RcOverrideFollowsFreshInputAndIsReleasedWithinTheTimeout) {
    auto config = apm2_config();
    config.rc_override.rate_hz = 10;
    config.rc_override.input_timeout = milliseconds(500);
    Rig rig(config, apm2_rover());
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::ManualNavigation, rig.now())).result,
              RequestResult::Ok);
    // Joystick at 5 Hz for 2 s: full right, half throttle.
    for (int i = 0; i < 10; ++i) {
        rig.driver.joystick(1.0, 0.5, rig.now());
        rig.harness.run_for(milliseconds(200));
        ASSERT_TRUE(rig.rover.last_override());
        EXPECT_EQ(rig.rover.last_override()->chan1_raw, 1900);
        EXPECT_EQ(rig.rover.last_override()->chan3_raw, 1700);
    }
    const auto sent_while_driving = rig.rover.overrides_received();
    EXPECT_GE(sent_while_driving, 18u);  // ~10 Hz
    EXPECT_LE(sent_while_driving, 22u);
    // Input stops (ground link lost): released within the timeout (+ one link transit).
    const TimePoint last_input = rig.now() - milliseconds(200);
    rig.harness.run_for(seconds(3));
    ASSERT_TRUE(rig.rover.last_override());
    EXPECT_EQ(rig.rover.last_override()->chan1_raw, 0);
    EXPECT_EQ(rig.rover.last_override()->chan3_raw, 0);
    EXPECT_LE(rig.rover.last_override_at() - last_input,
              config.rc_override.input_timeout + config.rc_override.release_repeats * milliseconds(100) +
                  milliseconds(50));
    const auto after_release = rig.rover.overrides_received();
    rig.harness.run_for(seconds(3));
    EXPECT_EQ(rig.rover.overrides_received(), after_release);  // nothing more once released
    EXPECT_EQ(rig.driver.rc_override().releases(), 1u);
}

TEST(Driver, JoystickIsIgnoredOutsideManualNavigation) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    rig.driver.joystick(1.0, 1.0, rig.now());
    rig.harness.run_for(seconds(1));
    EXPECT_EQ(rig.rover.overrides_received(), 0u);
}

TEST(Driver, WaypointReachedFromTextAndFromMessageOnce) {
    FakeRover::Options with_both;
    with_both.send_item_reached = true;
    auto config = AutopilotConfig::defaults_for(Board::Pixhawk);
    config.bauds = {115200};
    Rig rig(config, with_both);
    rig.bring_up();
    rig.rover.reach(1, rig.now());
    rig.harness.run_for(milliseconds(200));
    rig.rover.reach(2, rig.now());
    rig.harness.run_for(milliseconds(200));
    const auto reached = rig.all<WaypointReached>();
    ASSERT_EQ(reached.size(), 2u);
    EXPECT_EQ(reached[0].seq, 1);
    EXPECT_EQ(reached[1].seq, 2);

    Rig text_only(apm2_config(), apm2_rover());
    text_only.bring_up();
    text_only.rover.reach(3, text_only.now());
    text_only.harness.run_for(milliseconds(200));
    ASSERT_EQ(text_only.all<WaypointReached>().size(), 1u);
    EXPECT_EQ(text_only.all<WaypointReached>()[0].seq, 3);
}

std::vector<MissionItem> plan(std::size_t n) {
    std::vector<MissionItem> items;
    for (std::size_t i = 0; i < n; ++i) {
        MissionItem it;
        it.lat = 41.39 + 1e-5 * static_cast<double>(i);
        it.lon = 2.11 - 1e-5 * static_cast<double>(i);
        it.radius = 1.5;
        items.push_back(it);
    }
    items.back().kind = MissionItem::Kind::Stop;
    return items;
}

TEST(Driver, Upload150ItemsOverALossyRadioVerifiedByDownload) {
    LinkModel radio;
    radio.baud = 57600;
    radio.latency = milliseconds(20);
    radio.frame_drop = 0.10;
    auto config = AutopilotConfig::defaults_for(Board::Pixhawk);
    config.bauds = {57600};
    FakeRover::Options opts;
    opts.max_items = 200;
    Rig rig(config, opts, radio, 99);
    rig.bring_up();
    const auto items = plan(150);
    const auto up = rig.wait_result(rig.driver.upload_mission(items, rig.now()), seconds(600));
    ASSERT_EQ(up.result, RequestResult::Ok) << up.detail;
    const auto down = rig.wait_result(rig.driver.download_mission(rig.now()), seconds(600));
    ASSERT_EQ(down.result, RequestResult::Ok) << down.detail;
    ASSERT_EQ(down.items.size(), items.size());
    for (std::size_t i = 0; i < items.size(); ++i) {
        EXPECT_EQ(down.items[i].kind, items[i].kind) << i;
        EXPECT_NEAR(down.items[i].lat, items[i].lat, 1e-7) << i;
        EXPECT_NEAR(down.items[i].lon, items[i].lon, 1e-7) << i;
        ASSERT_TRUE(i + 1 == items.size() || down.items[i].radius) << i;
    }
    EXPECT_EQ(rig.driver.mission().size(), 150u);
}

TEST(Driver, PartialWriteAndSetCurrent) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(plan(6), rig.now())).result, RequestResult::Ok);
    MissionItem jump;
    jump.kind = MissionItem::Kind::JumpTo;
    jump.jump_slot = 1;
    ASSERT_EQ(rig.wait_result(rig.driver.write_items(6, {jump}, rig.now())).result, RequestResult::Ok);
    EXPECT_EQ(rig.rover.mission()[6].command, 177);
    EXPECT_EQ(rig.driver.mission()[5].kind, MissionItem::Kind::JumpTo);
    ASSERT_EQ(rig.wait_result(rig.driver.set_current(3, rig.now())).result, RequestResult::Ok);
    EXPECT_EQ(rig.rover.mission_current(), 3);
    rig.harness.run_for(seconds(2));
    EXPECT_EQ(rig.driver.status().mission_current, 3);
    EXPECT_EQ(rig.wait_result(rig.driver.write_items(0, {jump}, rig.now())).result, RequestResult::Invalid);
}

TEST(Driver, AWritesResultComesInItsPlaceAmongTheReportsReadWithIt) {
    // A slow daemon reads the board's answer to a write and the target report the board sent after it in one
    // read. The flight plan tells by their order whether the board took the slot before or after the write
    // landed: the result must come first, as the board sent it.
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(plan(6), rig.now())).result, RequestResult::Ok);
    const auto id = rig.driver.write_items(3, {plan(2).front()}, rig.now());
    while (rig.driver.poll_transmit()) {
    }  // the write's start; the board's side is played here by hand
    mav::Encoder board{1, 1, mav::Version::V1};
    mav::MissionRequest request;
    request.target_system = 255;
    request.target_component = 191;
    request.seq = 3;
    rig.driver.handle_bytes(board.encode(request), rig.now());
    ASSERT_TRUE(rig.driver.poll_transmit()) << "the item, asked for";
    mav::MissionAck ack;
    ack.target_system = 255;
    ack.target_component = 191;
    ack.type = mav::kMissionAccepted;
    mav::MissionCurrent current;
    current.seq = 3;
    auto read = board.encode(ack);
    const auto report = board.encode(current);
    read.insert(read.end(), report.begin(), report.end());
    rig.events.clear();
    rig.driver.handle_bytes(read, rig.now());
    rig.drain();

    std::optional<std::size_t> done_at, current_at;
    for (std::size_t i = 0; i < rig.events.size(); ++i) {
        if (const auto* d = std::get_if<RequestDone>(&rig.events[i]); d && d->id == id) {
            EXPECT_EQ(d->result, RequestResult::Ok) << d->detail;
            done_at = i;
        }
        if (const auto* c = std::get_if<MissionCurrentChanged>(&rig.events[i]); c && c->seq == 3) {
            current_at = i;
        }
    }
    ASSERT_TRUE(done_at && current_at);
    EXPECT_LT(*done_at, *current_at);
}

TEST(Driver, EachItemOfAWriteIsToldOnBoardWhenTheBoardAsksForTheNextInOrderWithItsReports) {
    // ArduPilot stores each item of a partial write as it comes and then asks for the next: the vehicle may
    // reach the first before the write's MISSION_ACK. The item is told on board at the request for the next
    // one, in its place among the reports read with it, before the write's result.
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(plan(8), rig.now())).result, RequestResult::Ok);
    auto items = plan(3);
    items[2].kind = MissionItem::Kind::Waypoint;
    const auto id = rig.driver.write_items(6, items, rig.now());
    while (rig.driver.poll_transmit()) {
    }
    mav::Encoder board{1, 1, mav::Version::V1};
    const auto request = [&](std::uint16_t seq) {
        mav::MissionRequest r;
        r.target_system = 255;
        r.target_component = 191;
        r.seq = seq;
        return board.encode(r);
    };
    rig.driver.handle_bytes(request(6), rig.now());
    rig.drain();
    EXPECT_TRUE(rig.all<MissionItemStored>().empty()) << "asked for its first item: nothing on board yet";
    rig.events.clear();
    mav::MissionItemReached reached;
    reached.seq = 6;
    auto read = request(7);
    const auto report = board.encode(reached);
    read.insert(read.end(), report.begin(), report.end());
    rig.driver.handle_bytes(read, rig.now());
    rig.drain();
    ASSERT_EQ(rig.events.size(), 2u);
    const auto* stored = std::get_if<MissionItemStored>(&rig.events[0]);
    ASSERT_NE(stored, nullptr) << "the item on board comes before the report read after it";
    EXPECT_EQ(stored->slot, 6);
    EXPECT_EQ(stored->item, items[0]);
    ASSERT_NE(std::get_if<WaypointReached>(&rig.events[1]), nullptr);
    EXPECT_FALSE(rig.result_of(id)) << "the write is still running";
}

TEST(Driver, RebootMidMissionIsDetectedAndResynced) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(plan(5), rig.now())).result, RequestResult::Ok);
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
              RequestResult::Ok);
    rig.harness.run_for(seconds(5));
    rig.rover.params()["CRUISE_SPEED"] = 2.0f;  // the reboot lost an unsaved parameter
    rig.rover.reboot(rig.now());
    ASSERT_TRUE(rig.run_until_event<AutopilotRebooted>(1, seconds(20)));
    ASSERT_TRUE(rig.run_until_event<Ready>(2, seconds(40))) << rig.driver.last_error();
    EXPECT_EQ(rig.driver.status().reboots, 1u);
    EXPECT_FLOAT_EQ(rig.rover.params()["CRUISE_SPEED"], 3.0f);  // re-applied
    EXPECT_EQ(rig.driver.mission().size(), 5u);                 // re-downloaded
    EXPECT_EQ(rig.driver.status().state, VehicleState::Parking);
    EXPECT_EQ(rig.all<AutopilotRebooted>().size(), 1u);
}

TEST(Driver, RebootDuringAHeartbeatSilenceIsDetectedByItsClock) {
    // A quick boot without calibration heartbeats or banners: only time_boot_ms tells.
    auto opts = apm2_rover();
    opts.calibration = Duration::zero();
    opts.boot_delay = milliseconds(500);
    opts.boot_texts = false;
    Rig rig(apm2_config(), opts);
    rig.bring_up();
    rig.harness.run_for(seconds(30));
    // Silent for 6 s, rebooting at the end of it: its clock restarted.
    rig.rover.stall(rig.now() + seconds(6));
    rig.harness.run_for(seconds(6));
    rig.rover.reboot(rig.now());
    ASSERT_TRUE(rig.run_until_event<AutopilotRebooted>(1, seconds(20)));
    ASSERT_TRUE(rig.run_until_event<Ready>(2, seconds(40)));
    EXPECT_EQ(rig.driver.status().reboots, 1u);
    EXPECT_NE(rig.all<AutopilotRebooted>()[0].evidence.find("time_boot_ms"), std::string::npos);
}

TEST(Driver, ABootAfterAHeartbeatGapIsSeenAtItsFirstHeartbeat) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    rig.harness.run_for(seconds(30));
    rig.rover.reboot(rig.now());  // silent for 2 s, then heartbeats saying CALIBRATING
    const TimePoint rebooted = rig.now();
    ASSERT_TRUE(rig.run_until_event<AutopilotRebooted>(1, seconds(20)));
    EXPECT_LE(rig.now() - rebooted, seconds(2) + milliseconds(100));
    EXPECT_NE(rig.all<AutopilotRebooted>()[0].evidence.find("heartbeat gap"), std::string::npos)
        << rig.all<AutopilotRebooted>()[0].evidence;
    ASSERT_TRUE(rig.run_until_event<Ready>(2, seconds(40)));
    EXPECT_EQ(rig.driver.status().reboots, 1u);
    EXPECT_EQ(rig.driver.status().syncs, 2u);
    EXPECT_EQ(rig.all<AutopilotRebooted>().size(), 1u);
}

// A boot shorter than the heartbeat gap that counts (a simulator at a speedup, heartbeats read late) is
// declared at its first heartbeat in INITIALISING, not 1.5 s later when the clock has run on: meanwhile a
// flight plan would have driven the booted board on the mission it kept. The clock's evidence of the same
// boot is no second reboot.
TEST(Driver, AShortBootIsSeenAtItsFirstHeartbeatInTheBootMode) {
    auto opts = apm2_rover();
    opts.boot_delay = milliseconds(300);
    opts.boot_texts = false;
    Rig rig(apm2_config(), opts);
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
              RequestResult::Ok);
    rig.harness.run_for(seconds(30));
    rig.rover.report_initialising(rig.now() + opts.boot_delay + opts.calibration);
    rig.rover.reboot(rig.now());
    const TimePoint rebooted = rig.now();
    ASSERT_TRUE(rig.run_until_event<AutopilotRebooted>(1, seconds(20)));
    EXPECT_LE(rig.now() - rebooted, seconds(1) + opts.boot_delay + milliseconds(100));
    EXPECT_NE(rig.all<AutopilotRebooted>()[0].evidence.find("from AUTO to INITIALISING"), std::string::npos)
        << rig.all<AutopilotRebooted>()[0].evidence;
    ASSERT_TRUE(rig.run_until_event<Ready>(2, seconds(40)));
    rig.harness.run_for(seconds(30));
    EXPECT_EQ(rig.driver.status().reboots, 1u);
    EXPECT_EQ(rig.driver.status().syncs, 2u);
    EXPECT_EQ(rig.all<AutopilotRebooted>().size(), 1u);
}

// Current ArduPilot answers every PARAM_REQUEST_LIST with its banner ("ArduRover V4.x (hash)", the OS and
// board lines): the daemon's own request, and every other station's. A banner is no reboot: it used to be
// taken for one within 10 s of the link coming up, which asked for the parameters again, which brought the
// banner again, until the 10 s were over.
TEST(Driver, TheBannerOnEveryParameterListIsNoReboot) {
    auto config = AutopilotConfig::defaults_for(Board::Pixhawk);
    config.bauds = {115200};
    FakeRover::Options o;
    o.banner_on_param_list = true;
    Rig rig(config, o);
    rig.open_with_reset();
    const TimePoint opened = rig.now();
    ASSERT_TRUE(rig.run_until_event<Ready>(1, seconds(40))) << rig.driver.last_error();
    const double took = std::chrono::duration<double>(rig.now() - opened).count();
    EXPECT_LE(took, 2.0 + 1.0 + 1.0);
    ASSERT_TRUE(rig.driver.status().ready_s);
    EXPECT_NEAR(*rig.driver.status().ready_s, took, 1e-6) << "from the port's open";
    // Another station asks for the parameter list every 30 s for 10 minutes.
    for (int i = 0; i < 20; ++i) {
        rig.rover.parameter_list_asked(rig.now());
        rig.harness.run_for(seconds(30));
    }
    std::size_t banners = 0;
    for (const auto& t : rig.all<StatusText>()) {
        banners += t.text.starts_with("ArduRover V4") ? 1 : 0;
    }
    EXPECT_EQ(banners, 21u);
    EXPECT_TRUE(rig.all<AutopilotRebooted>().empty()) << rig.all<AutopilotRebooted>()[0].evidence;
    EXPECT_EQ(rig.driver.status().reboots, 0u);
    EXPECT_EQ(rig.driver.status().syncs, 1u) << "the parameters and the mission were read once";
    EXPECT_EQ(rig.all<Ready>().size(), 1u);
    EXPECT_TRUE(rig.driver.ready());
}

// airsegd itself stopped (SIGSTOP) or starved for 1.5-5 s while the board streams on: when it runs again its
// timer and its port are ready at once, and the timer is served first (the worst order). The heartbeats and
// the clock samples sent meanwhile are in the port; the link was never lost and the board never rebooted.
TEST(Driver, TheDaemonsOwnStallsAreNotTheAutopilotsSilence) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    rig.harness.run_for(seconds(20));
    const auto link_downs = rig.all<LinkDown>().size();
    for (const Duration stall : {milliseconds(1500), milliseconds(2100), milliseconds(3300),
                                 milliseconds(4200), milliseconds(5000), milliseconds(2950)}) {
        rig.harness.stall_ground(rig.now() + stall);
        rig.harness.run_for(stall + seconds(7));
    }
    EXPECT_EQ(rig.all<LinkDown>().size(), link_downs);
    EXPECT_TRUE(rig.all<AutopilotRebooted>().empty()) << rig.all<AutopilotRebooted>()[0].evidence;
    EXPECT_EQ(rig.driver.status().reboots, 0u);
    EXPECT_EQ(rig.driver.status().link_losses, 0u);
    EXPECT_EQ(rig.driver.status().syncs, 1u) << "no parameter or mission re-download";
    EXPECT_EQ(rig.all<Ready>().size(), 1u);
    EXPECT_TRUE(rig.driver.ready());
}

// A board that really stops during the daemon's stall is still found silent, a grace later.
TEST(Driver, ABoardSilentAcrossTheDaemonsStallIsStillLost) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    const TimePoint t0 = rig.now();
    rig.rover.stall(t0 + seconds(30));
    rig.harness.stall_ground(t0 + seconds(4));
    ASSERT_TRUE(rig.run_until_event<LinkDown>(1, seconds(10)));
    EXPECT_LE(rig.now() - t0, seconds(4) + LinkWatch::kReadGrace + milliseconds(10));
    EXPECT_EQ(rig.driver.status().link_losses, 1u);
}

TEST(Driver, HeartbeatStallOfTenSecondsIsLinkDownThenUpWithoutReboot) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    const TimePoint stall = rig.now();
    rig.rover.stall(stall + seconds(10));
    ASSERT_TRUE(rig.run_until_event<LinkDown>(1, seconds(10)));
    EXPECT_LE(rig.now() - stall, seconds(3) + seconds(1));  // heartbeat_timeout after the last heartbeat
    EXPECT_FALSE(rig.driver.status().link_up);
    EXPECT_EQ(rig.driver.status().state, VehicleState::Unknown);
    EXPECT_EQ(rig.wait_result(rig.driver.set_current(1, rig.now())).result, RequestResult::NotReady);
    ASSERT_TRUE(rig.run_until_event<LinkUp>(2, seconds(15)));
    rig.harness.run_for(seconds(2));
    EXPECT_TRUE(rig.driver.ready());
    EXPECT_EQ(rig.driver.status().reboots, 0u);
    EXPECT_EQ(rig.driver.status().state, VehicleState::Parking);
}

TEST(Driver, UnresponsiveAutopilotGetsAtMostNResetPulses) {
    auto config = apm2_config();
    config.reset_on_open = false;
    config.unresponsive_timeout = seconds(5);
    config.max_reset_pulses = 2;
    Rig rig(config, apm2_rover());
    rig.rover.stall(kDriverTestStart + std::chrono::hours(1));
    rig.driver.on_port_open(rig.now());
    rig.harness.run_until(
        [&] {
            for (auto& a : rig.actions) {
                if (std::holds_alternative<PulseReset>(a)) {
                    a = SwitchBaud{0};  // consumed: the service pulsed the line
                    rig.driver.on_reset_pulsed(rig.now());
                }
            }
            return false;
        },
        rig.now() + seconds(60));
    EXPECT_EQ(rig.driver.status().reset_pulses, 2u);
    EXPECT_NE(rig.driver.last_error().find("exhausted"), std::string::npos) << rig.driver.last_error();
}

TEST(Driver, ResetPulseRecoversAStuckAutopilot) {
    auto config = apm2_config();
    config.reset_on_open = false;
    config.unresponsive_timeout = seconds(5);
    Rig rig(config, apm2_rover());
    rig.rover.stall(kDriverTestStart + std::chrono::hours(1));
    rig.driver.on_port_open(rig.now());
    const bool ready = rig.harness.run_until(
        [&] {
            for (auto& a : rig.actions) {
                if (std::holds_alternative<PulseReset>(a)) {
                    a = SwitchBaud{0};
                    rig.rover.stall(rig.now());  // the reset line reboots it
                    rig.rover.reboot(rig.now());
                    rig.driver.on_reset_pulsed(rig.now());
                }
            }
            return !rig.all<Ready>().empty();
        },
        rig.now() + seconds(60));
    EXPECT_TRUE(ready) << rig.driver.last_error();
    EXPECT_EQ(rig.driver.status().reset_pulses, 1u);
}

TEST(Driver, BaudProbingMovesToTheNextRateUntilAFrameArrives) {
    auto config = apm2_config();
    config.bauds = {57600, 115200};
    config.baud_probe = seconds(2);
    Rig rig(config, apm2_rover());
    rig.rover.stall(kDriverTestStart + seconds(3));  // nothing readable at first
    rig.open_with_reset();
    rig.rover.stall(kDriverTestStart + seconds(3));
    ASSERT_TRUE(rig.run_until_event<Ready>(1, seconds(40)));
    ASSERT_FALSE(rig.actions.empty());
    ASSERT_TRUE(std::holds_alternative<SwitchBaud>(rig.actions[0]));
    EXPECT_EQ(std::get<SwitchBaud>(rig.actions[0]).baud, 115200u);
    EXPECT_EQ(rig.driver.current_baud(), 115200u);
    rig.harness.run_for(seconds(10));
    EXPECT_EQ(rig.actions.size(), 1u);  // kept once frames arrived
}

TEST(Driver, ParameterGetAndSetWithReadBack) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    const auto got = rig.wait_result(rig.driver.get_param("PARAM_7", rig.now()));
    ASSERT_EQ(got.result, RequestResult::Ok) << got.detail;
    EXPECT_DOUBLE_EQ(*got.param_value, 7.0);
    const auto set = rig.wait_result(rig.driver.set_param("PARAM_7", 12.5, rig.now()));
    ASSERT_EQ(set.result, RequestResult::Ok) << set.detail;
    EXPECT_FLOAT_EQ(rig.rover.params()["PARAM_7"], 12.5f);
    EXPECT_FLOAT_EQ(*rig.driver.params().cached("PARAM_7"), 12.5f);
    const auto missing = rig.wait_result(rig.driver.set_param("NO_SUCH_PARAM", 1, rig.now()));
    EXPECT_EQ(missing.result, RequestResult::Timeout);
    const auto bad = rig.wait_result(rig.driver.set_param("A_NAME_LONGER_THAN_16", 1, rig.now()));
    EXPECT_EQ(bad.result, RequestResult::Invalid);
}

TEST(Driver, UnknownConfiguredParameterKeepsTheDriverFromReady) {
    auto config = apm2_config();
    config.params.push_back({"NOT_A_PARAM", 1});
    Rig rig(config, apm2_rover());
    rig.open_with_reset();
    EXPECT_FALSE(rig.run_until_event<Ready>(1, seconds(20)));
    EXPECT_NE(rig.driver.last_error().find("NOT_A_PARAM"), std::string::npos) << rig.driver.last_error();
}

TEST(Driver, PortClosedCancelsAndReportsDown) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    const auto id = rig.driver.download_mission(rig.now());
    rig.driver.on_port_closed("no /dev/ttyACM0", rig.now());
    rig.drain();
    ASSERT_TRUE(rig.result_of(id));
    EXPECT_EQ(rig.result_of(id)->result, RequestResult::Cancelled);
    ASSERT_EQ(rig.all<LinkDown>().size(), 1u);
    EXPECT_EQ(rig.all<LinkDown>()[0].reason, "no /dev/ttyACM0");
    EXPECT_FALSE(rig.driver.ready());
}

TEST(Driver, TelemetryFromTheStreams) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    rig.harness.run_for(seconds(2));
    const auto& t = rig.driver.telemetry();
    ASSERT_TRUE(t.position);
    EXPECT_NEAR(t.position->lat, 41.39, 0.01);
    EXPECT_NEAR(t.position->alt, 12.0, 1e-9);
    EXPECT_NEAR(t.heading, 90.0, 1e-9);
    EXPECT_EQ(t.mode, "HOLD");
    EXPECT_EQ(t.custom_mode, std::optional<std::uint32_t>(4));
    ASSERT_TRUE(rig.driver.status().position);
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot

namespace airseg::autopilot::ardupilot {
namespace {

// --- firmware eras: what each board takes -----------------------------------------------------------------

AutopilotConfig pixhawk_config() {
    auto c = AutopilotConfig::defaults_for(Board::Pixhawk);
    c.params = {{"CRUISE_SPEED", 3.0}};
    return c;
}

FakeRover::Options strict_float_rover() {
    FakeRover::Options o = apm2_rover();
    o.accepted_frames = {0, 2, 3};  // MAV_FRAME_GLOBAL, MISSION, GLOBAL_RELATIVE_ALT
    return o;
}

std::size_t count_int_items(const FakeRover& rover) {
    std::size_t n = 0;
    for (const auto& [msgid, frame] : rover.item_frames()) {
        n += msgid == mav::MissionItemInt::kId;
    }
    return n;
}

TEST(Driver, OurHeartbeatGoesToTheAutopilotAtOneHertzWithTheConfiguredType) {
    auto config = apm2_config();
    config.gcs_heartbeat_type = kMavTypeOnboardController;
    Rig rig(config, apm2_rover());
    std::vector<TimePoint> sent;
    mav::Parser parser;
    rig.driver.set_frame_tap([&](bool outgoing, std::span<const std::uint8_t> frame) {
        if (!outgoing) {
            return;
        }
        parser.push(frame, [&](const mav::Frame& f) {
            if (f.msgid == mav::Heartbeat::kId) {
                EXPECT_EQ(mav::decode_payload<mav::Heartbeat>(f.payload_view()).type,
                          kMavTypeOnboardController);
                sent.push_back(rig.now());
            }
        });
    });
    rig.bring_up();
    const TimePoint from = rig.now();
    const std::size_t before = sent.size();
    rig.harness.run_for(seconds(20));
    // Nothing else asks for the driver's attention in a quiet READY state: the heartbeat keeps its own time.
    EXPECT_GE(sent.size() - before, 19u);
    EXPECT_LE(sent.size() - before, 21u);
    for (std::size_t i = before + 1; i < sent.size(); ++i) {
        EXPECT_LE(sent[i] - sent[i - 1], milliseconds(1050)) << "gap before heartbeat " << i;
    }
    EXPECT_GT(sent.front(), kDriverTestStart - seconds(1));
    (void)from;
}

TEST(Driver, FloatMissionItemsCarryFloatFramesOnABoardThatTakesOnlyThose) {
    Rig rig(apm2_config(), strict_float_rover());
    rig.bring_up();
    const auto r = rig.wait_result(rig.driver.upload_mission(plan(8), rig.now()));
    ASSERT_EQ(r.result, RequestResult::Ok) << r.detail;
    ASSERT_EQ(rig.rover.item_frames().size(), 9u);  // home (slot 0) and the 8 items
    for (std::size_t i = 0; i < rig.rover.item_frames().size(); ++i) {
        const auto [msgid, frame] = rig.rover.item_frames()[i];
        EXPECT_EQ(msgid, mav::MissionItem::kId);
        // Home in MAV_FRAME_GLOBAL; the rest MAV_FRAME_GLOBAL_RELATIVE_ALT, never frame 6 in a MISSION_ITEM.
        EXPECT_EQ(frame, i == 0 ? 0 : 3) << "item " << i;
    }
    EXPECT_EQ(rig.rover.mission()[1].frame, 3);
    EXPECT_EQ(rig.driver.status().mission_items, "float");
}

TEST(Driver, ABoardRefusingMissionItemIntGetsFloatItemsOnceAndForAll) {
    FakeRover::Options o = strict_float_rover();
    o.version = mav::Version::V2;
    Rig rig(pixhawk_config(), o);
    rig.bring_up();
    ASSERT_EQ(rig.driver.status().mission_items, "int");
    const auto r = rig.wait_result(rig.driver.upload_mission(plan(8), rig.now()));
    ASSERT_EQ(r.result, RequestResult::Ok) << r.detail;
    // Home and item 1 went as MISSION_ITEM_INT; item 1 was refused, then everything as MISSION_ITEM.
    EXPECT_EQ(count_int_items(rig.rover), 2u);
    EXPECT_EQ(rig.rover.mission()[8].frame, 3);
    EXPECT_EQ(rig.driver.status().mission_items, "float");
    EXPECT_EQ(rig.driver.mission_client().stats().float_fallbacks, 1u);
    // Remembered: the next write goes as MISSION_ITEM at once.
    MissionItem wp = plan(2).front();
    ASSERT_EQ(rig.wait_result(rig.driver.write_items(2, {wp}, rig.now())).result, RequestResult::Ok);
    EXPECT_EQ(count_int_items(rig.rover), 2u);
}

TEST(Driver, ARefusalOfTheFloatFormIsFinalAndNamesTheBoardsAnswer) {
    FakeRover::Options o = strict_float_rover();
    o.accepted_frames = {2};  // a board that takes no global frame at all
    Rig rig(apm2_config(), o);
    rig.bring_up();
    const TimePoint start = rig.now();
    const auto r = rig.wait_result(rig.driver.upload_mission(plan(4), rig.now()));
    EXPECT_EQ(r.result, RequestResult::Refused);
    EXPECT_NE(r.detail.find("MAV_MISSION_UNSUPPORTED_FRAME"), std::string::npos) << r.detail;
    EXPECT_NE(r.detail.find("MISSION_ITEM"), std::string::npos) << r.detail;
    EXPECT_LT(rig.now() - start, seconds(5)) << "a refusal is an answer, not a reason to retry";
    EXPECT_LE(rig.rover.item_frames().size(), 2u);
}

TEST(Driver, EnteringAutoOnABoardThatRestartsAtItemOneGoesBackToTheSlotItWasAt) {
    FakeRover::Options o = apm2_rover();
    o.restart_mission_on_auto = true;
    Rig rig(apm2_config(), o);
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(plan(8), rig.now())).result, RequestResult::Ok);
    ASSERT_EQ(rig.wait_result(rig.driver.set_current(5, rig.now())).result, RequestResult::Ok);
    rig.harness.run_for(seconds(2));
    const std::size_t events_before = rig.events.size();
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
              RequestResult::Ok);
    rig.harness.run_for(seconds(4));
    EXPECT_EQ(rig.rover.mission_current(), 5) << "the board must be set back to the slot it was at";
    EXPECT_EQ(rig.driver.status().auto_restarts_corrected, 1u);
    for (std::size_t i = events_before; i < rig.events.size(); ++i) {
        if (const auto* c = std::get_if<MissionCurrentChanged>(&rig.events[i])) {
            EXPECT_EQ(c->seq, 5) << "the restart to item 1 must not reach the flight plan manager";
        }
    }
    // A board that keeps its slot is left alone.
    Rig modern(pixhawk_config(), FakeRover::Options{});
    modern.bring_up();
    ASSERT_EQ(modern.wait_result(modern.driver.upload_mission(plan(8), modern.now())).result,
              RequestResult::Ok);
    ASSERT_EQ(modern.wait_result(modern.driver.set_current(5, modern.now())).result, RequestResult::Ok);
    ASSERT_EQ(modern.wait_result(modern.driver.request_state(VehicleState::WaypointNavigation, modern.now()))
                  .result,
              RequestResult::Ok);
    modern.harness.run_for(seconds(4));
    EXPECT_EQ(modern.rover.mission_current(), 5);
    EXPECT_EQ(modern.driver.status().auto_restarts_corrected, 0u);
}

TEST(Driver, ABoardWithoutLoiterUnlimGetsStopsAsJumpsPastTheEnd) {
    FakeRover::Options o = apm2_rover();
    o.loiter_unlim = false;
    Rig rig(apm2_config(), o);
    rig.bring_up();
    const auto r = rig.wait_result(rig.driver.upload_mission(plan(6), rig.now()));  // slot 6 is a Stop
    ASSERT_EQ(r.result, RequestResult::Ok) << r.detail;
    EXPECT_TRUE(rig.driver.stops_as_jumps());
    EXPECT_EQ(r.stop_ends_mission, std::optional<bool>(true)) << "the flight plan manager is told";
    EXPECT_EQ(rig.rover.mission()[6].command, 177) << "MAV_CMD_DO_JUMP";
    EXPECT_EQ(rig.rover.mission()[6].param1, 255.0f) << "past the end of any mission the board holds";
    EXPECT_EQ(rig.driver.mission()[5].kind, MissionItem::Kind::Stop)
        << "still a Stop to the rest of the daemon";
    // The board holds there by itself: the driver sends no HOLD of its own on arrival.
    ASSERT_EQ(rig.wait_result(rig.driver.set_current(5, rig.now())).result, RequestResult::Ok);
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
              RequestResult::Ok);
    rig.harness.run_for(seconds(2));
    rig.rover.reach(5, rig.now());
    rig.harness.run_for(seconds(2));
    EXPECT_EQ(rig.rover.mode(), testing::kAuto) << "no HOLD from the driver";
}

// The flight plan manager learns from a write's result how the board runs a Stop, once one was written: a
// board with NAV_LOITER_UNLIM loiters there in AUTO. Before that the result says nothing either way.
TEST(Driver, AWriteResultSaysHowTheBoardRunsAStopOnceOneWasWritten) {
    Rig rig(pixhawk_config(), FakeRover::Options{});
    rig.bring_up();
    auto places = plan(6);
    places.back().kind = MissionItem::Kind::Waypoint;
    const auto first = rig.wait_result(rig.driver.upload_mission(places, rig.now()));
    ASSERT_EQ(first.result, RequestResult::Ok) << first.detail;
    EXPECT_EQ(first.stop_ends_mission, std::nullopt) << "no Stop written yet";
    const auto with_stop = rig.wait_result(rig.driver.write_items(6, {plan(6).back()}, rig.now()));
    ASSERT_EQ(with_stop.result, RequestResult::Ok) << with_stop.detail;
    EXPECT_EQ(with_stop.stop_ends_mission, std::optional<bool>(false));
    EXPECT_FALSE(rig.driver.stops_as_jumps());
}

TEST(Driver, HoldReportedAsUninitByA2xBoardIsNoReboot) {
    FakeRover::Options o = apm2_rover();
    o.uninit_in_hold = true;
    Rig rig(apm2_config(), o);
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::Parking, rig.now())).result,
              RequestResult::Ok);
    rig.harness.run_for(seconds(5));
    EXPECT_TRUE(rig.all<AutopilotRebooted>().empty());
    EXPECT_TRUE(rig.driver.ready());
    EXPECT_EQ(rig.driver.status().state, VehicleState::Parking);
}

std::vector<MissionItem> plan_with_speeds() {
    auto items = plan(8);
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (i < 6) {
            items[i].speed = i < 3 ? 1.5 : 2.5;  // the last two legs have none: the board's own speed
        }
    }
    return items;
}

TEST(Driver, TheLegSpeedGoesByCommandOnBoardsThatHaveItAndByCruiseSpeedOnOthers) {
    // Pixhawk-era: MAV_CMD_DO_CHANGE_SPEED, once per change.
    Rig modern(pixhawk_config(), FakeRover::Options{});
    modern.bring_up();
    ASSERT_EQ(modern.wait_result(modern.driver.upload_mission(plan_with_speeds(), modern.now())).result,
              RequestResult::Ok);
    ASSERT_EQ(modern.wait_result(modern.driver.set_current(1, modern.now())).result, RequestResult::Ok);
    ASSERT_EQ(modern.wait_result(modern.driver.request_state(VehicleState::WaypointNavigation, modern.now()))
                  .result,
              RequestResult::Ok);
    modern.harness.run_for(seconds(2));
    ASSERT_EQ(modern.rover.speed_commands(), std::vector<float>{1.5F});
    ASSERT_EQ(modern.wait_result(modern.driver.set_current(2, modern.now())).result, RequestResult::Ok);
    modern.harness.run_for(seconds(2));
    EXPECT_EQ(modern.rover.speed_commands(), std::vector<float>{1.5F}) << "same speed: nothing sent";
    ASSERT_EQ(modern.wait_result(modern.driver.set_current(5, modern.now())).result, RequestResult::Ok);
    modern.harness.run_for(seconds(2));
    EXPECT_EQ(modern.rover.speed_commands(), (std::vector<float>{1.5F, 2.5F}));
    EXPECT_EQ(modern.driver.status().speed, 2.5);
    ASSERT_EQ(modern.wait_result(modern.driver.set_current(7, modern.now())).result, RequestResult::Ok);
    modern.harness.run_for(seconds(2));
    EXPECT_EQ(modern.rover.speed_commands(), (std::vector<float>{1.5F, 2.5F, 3.0F}))
        << "a leg without a speed goes back to the board's CRUISE_SPEED";

    // APM 2.x: no such command; CRUISE_SPEED is written (and read back).
    Rig old(apm2_config(), apm2_rover());
    old.bring_up();
    ASSERT_EQ(old.wait_result(old.driver.upload_mission(plan_with_speeds(), old.now())).result,
              RequestResult::Ok);
    ASSERT_EQ(old.wait_result(old.driver.set_current(5, old.now())).result, RequestResult::Ok);
    ASSERT_EQ(old.wait_result(old.driver.request_state(VehicleState::WaypointNavigation, old.now())).result,
              RequestResult::Ok);
    old.harness.run_for(seconds(3));
    EXPECT_TRUE(old.rover.speed_commands().empty());
    EXPECT_FLOAT_EQ(old.rover.params()["CRUISE_SPEED"], 2.5F);
    EXPECT_EQ(old.driver.status().speed, 2.5);

    // A board that refuses the command: CRUISE_SPEED from then on.
    FakeRover::Options refusing;
    refusing.change_speed_command = false;
    Rig odd(pixhawk_config(), refusing);
    odd.bring_up();
    ASSERT_EQ(odd.wait_result(odd.driver.upload_mission(plan_with_speeds(), odd.now())).result,
              RequestResult::Ok);
    ASSERT_EQ(odd.wait_result(odd.driver.set_current(1, odd.now())).result, RequestResult::Ok);
    ASSERT_EQ(odd.wait_result(odd.driver.request_state(VehicleState::WaypointNavigation, odd.now())).result,
              RequestResult::Ok);
    odd.harness.run_for(seconds(3));
    EXPECT_FLOAT_EQ(odd.rover.params()["CRUISE_SPEED"], 1.5F);
    EXPECT_TRUE(odd.driver.speed_by_param());
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot

namespace airseg::autopilot::ardupilot {
namespace {

// ---- arming (ArduPilot Rover 4.x boots disarmed: ARMING_REQUIRE 1) ---------------------------------------

FakeRover::Options needs_arming() {
    FakeRover::Options o;
    o.arming_required = true;
    return o;
}

TEST(Driver, ABoardThatNeedsArmingIsArmedOnceAutoIsConfirmedAndStaysArmedInHold) {
    Rig rig(pixhawk_config(), needs_arming());
    rig.bring_up();
    EXPECT_EQ(rig.driver.status().armed, std::optional<bool>(false));
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(plan(4), rig.now())).result, RequestResult::Ok);
    const auto id = rig.driver.request_state(VehicleState::WaypointNavigation, rig.now());
    const auto r = rig.wait_result(id);
    ASSERT_EQ(r.result, RequestResult::Ok) << r.detail;
    EXPECT_EQ(r.armed, std::optional<bool>(true));
    EXPECT_TRUE(rig.rover.armed());
    EXPECT_EQ(rig.rover.mode(), testing::kAuto);
    EXPECT_EQ(rig.rover.arm_commands(), 1u);
    EXPECT_EQ(rig.driver.status().armed, std::optional<bool>(true));
    // PARKING and AUTO again: nothing disarms, nothing arms twice.
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::Parking, rig.now())).result,
              RequestResult::Ok);
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
              RequestResult::Ok);
    EXPECT_TRUE(rig.rover.armed());
    EXPECT_EQ(rig.rover.arm_commands(), 1u);
}

TEST(Driver, ArmingRefusedEndsTheRequestRefusedInTheBoardsOwnWords) {
    auto opts = needs_arming();
    opts.arm_refusal = "Need Position Estimate";
    Rig rig(pixhawk_config(), opts);
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(plan(4), rig.now())).result, RequestResult::Ok);
    const auto r = rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now()));
    EXPECT_EQ(r.result, RequestResult::Refused);
    EXPECT_NE(r.detail.find("Arm: Need Position Estimate"), std::string::npos) << r.detail;
    EXPECT_NE(r.detail.find("MAV_RESULT_FAILED"), std::string::npos) << r.detail;
    EXPECT_EQ(r.armed, std::optional<bool>(false));
    EXPECT_EQ(rig.driver.status().arm_refusals, 1u);
    EXPECT_EQ(rig.driver.arm_control().last_refusal(), "Arm: Need Position Estimate");
    EXPECT_EQ(rig.rover.arm_commands(), 1u) << "a refusal is not asked again";
}

TEST(Driver, WithArmingNeverTheBoardIsLeftAsItIsAndAnUnansweredArmTimesOut) {
    auto never = pixhawk_config();
    never.arming = ArmingPolicy::Never;
    Rig rig(never, needs_arming());
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(plan(4), rig.now())).result, RequestResult::Ok);
    EXPECT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
              RequestResult::Ok);
    EXPECT_EQ(rig.rover.arm_commands(), 0u);
    EXPECT_FALSE(rig.rover.armed());

    auto silent = needs_arming();
    silent.arm_acks = false;
    Rig mute(pixhawk_config(), silent);
    mute.bring_up();
    ASSERT_EQ(mute.wait_result(mute.driver.upload_mission(plan(4), mute.now())).result, RequestResult::Ok);
    const auto r = mute.wait_result(mute.driver.request_state(VehicleState::WaypointNavigation, mute.now()));
    EXPECT_EQ(r.result, RequestResult::Timeout) << r.detail;
    EXPECT_EQ(mute.rover.arm_commands(), 1u + pixhawk_config().mode_retries);
}

TEST(Driver, AJoystickSessionArmsTooButTheRcPilotsDirectedStateDoesNot) {
    Rig rig(pixhawk_config(), needs_arming());
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::Directed, rig.now())).result,
              RequestResult::Ok);
    EXPECT_FALSE(rig.rover.armed());
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::ManualNavigation, rig.now())).result,
              RequestResult::Ok);
    EXPECT_TRUE(rig.rover.armed());
}

// ---- speeds on current Rover: the board forgets the command's speed at every entry into AUTO
// ---------------

TEST(Driver, ThePlansSpeedIsSetAgainAfterEveryEntryIntoAutoAndStatusShowsWhatTheBoardConfirmed) {
    FakeRover::Options current;
    current.current_rover_speed = true;
    Rig rig(pixhawk_config(), current);
    rig.bring_up();
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(plan_with_speeds(), rig.now())).result,
              RequestResult::Ok);
    ASSERT_EQ(rig.wait_result(rig.driver.set_current(1, rig.now())).result, RequestResult::Ok);
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
              RequestResult::Ok);
    rig.harness.run_for(seconds(2));
    ASSERT_EQ(rig.rover.speed_commands(), std::vector<float>{1.5F});
    EXPECT_EQ(rig.driver.status().speed, 1.5);
    EXPECT_STREQ(rig.driver.speed_param(), "WP_SPEED");

    // HOLD and back (a forced HOLD, a pause): the board drives at WP_SPEED again; the plan's speed follows.
    rig.rover.pilot_sets_mode(testing::kHold, rig.now());
    rig.harness.run_for(seconds(2));
    rig.rover.pilot_sets_mode(testing::kAuto, rig.now());
    rig.harness.run_until([&] { return rig.driver.status().mode == "AUTO"; }, rig.now() + seconds(5));
    EXPECT_EQ(rig.driver.status().speed, std::optional<double>(2.0)) << "WP_SPEED until confirmed";
    rig.harness.run_for(seconds(2));
    EXPECT_EQ(rig.rover.speed_commands(), (std::vector<float>{1.5F, 1.5F}));
    EXPECT_EQ(rig.driver.status().speed, 1.5);
    EXPECT_FALSE(rig.driver.speed_by_param()) << "FAILED outside AUTO is not a board without the command";
}

TEST(Driver, OnABoardSetByParameterItsOwnSpeedIsWrittenBackWhenThePlanEnds) {
    Rig old(apm2_config(), apm2_rover());
    old.bring_up();
    ASSERT_FLOAT_EQ(old.rover.params()["CRUISE_SPEED"], 3.0F);
    ASSERT_EQ(old.wait_result(old.driver.upload_mission(plan_with_speeds(), old.now())).result,
              RequestResult::Ok);
    ASSERT_EQ(old.wait_result(old.driver.set_current(5, old.now())).result, RequestResult::Ok);
    ASSERT_EQ(old.wait_result(old.driver.request_state(VehicleState::WaypointNavigation, old.now())).result,
              RequestResult::Ok);
    old.harness.run_for(seconds(3));
    ASSERT_FLOAT_EQ(old.rover.params()["CRUISE_SPEED"], 2.5F);
    // The last waypoint reached: the board heads for the plan's final Stop.
    ASSERT_EQ(old.wait_result(old.driver.set_current(8, old.now())).result, RequestResult::Ok);
    old.harness.run_for(seconds(3));
    EXPECT_FLOAT_EQ(old.rover.params()["CRUISE_SPEED"], 3.0F) << "the board's own value, back";
    EXPECT_EQ(old.driver.status().speed, 3.0);
}

// A board whose heartbeat says INITIALISING while the daemon holds it ready (the first heartbeats of a reboot
// too short for a heartbeat gap, whose clock evidence has not come in yet) is declared rebooted at once, and
// will take a mode once it is up: the request is "not ready", asked again later, never a refusal (the flight
// plan fails a plan whose AUTO is refused).
TEST(Driver, AModeAskedWhileTheBoardSaysItIsBootingIsNotReadyRatherThanRefused) {
    Rig rig(apm2_config(), apm2_rover());
    rig.bring_up();
    rig.harness.run_for(seconds(10));
    rig.rover.report_initialising(rig.now() + seconds(3));
    ASSERT_TRUE(rig.harness.run_until(
        [&] { return rig.driver.status().state == VehicleState::ConfigureCheck; }, rig.now() + seconds(5)));
    const auto asked = rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now()));
    EXPECT_EQ(asked.result, RequestResult::NotReady) << asked.detail;
    EXPECT_EQ(rig.driver.status().reboots, 1u) << "Rover holds INITIALISING only while it boots";
    ASSERT_TRUE(rig.harness.run_until(
        [&] { return rig.driver.status().state != VehicleState::ConfigureCheck; }, rig.now() + seconds(10)));
    EXPECT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
              RequestResult::Ok);
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot
