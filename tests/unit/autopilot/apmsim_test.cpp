// The driver core against the simulated APM:Rover board (tools/apmsim), both in-process, bytes between them,
// in simulated time: the acceptance scenarios of the autopilot layer.
#include <gtest/gtest.h>

#include <deque>
#include <iostream>
#include <map>

#include "services/autopilot/ardupilot/driver.hpp"
#include "tests/unit/autopilot/sim_harness.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::autopilot::ardupilot {
namespace {

using testing::Harness;
using testing::LinkModel;
using testing::Party;
namespace mav = airseg::mavlink;

const TimePoint kStart = TimePoint{} + std::chrono::hours(3);

apmsim::RoverSimConfig sim_config(Board board) {
    apmsim::RoverSimConfig c;
    c.version = board == Board::Apm2 ? mav::Version::V1 : mav::Version::V2;
    c.reached_style =
        board == Board::Apm2 ? apmsim::ReachedStyle::TextOnly : apmsim::ReachedStyle::MessageAndText;
    c.mission_capacity = 300;
    c.reset_on_open = board == Board::Apm2;
    return c;
}

AutopilotConfig driver_config(Board board) {
    auto c = AutopilotConfig::defaults_for(board);
    c.bauds = {115200};
    return c;
}

struct SimRig {
    SimRig(Board board, LinkModel up = {}, LinkModel down = {}, std::uint32_t seed = 5)
        : SimRig(driver_config(board), sim_config(board), up, down, seed) {}
    SimRig(AutopilotConfig config, apmsim::RoverSimConfig sc, LinkModel up, LinkModel down,
           std::uint32_t seed)
        : driver(std::move(config)), sim(sc, kStart), harness(ground(), board(), up, down, seed, kStart) {}

    Party ground() {
        Party p;
        p.receive = [this](std::span<const std::uint8_t> b, TimePoint now) {
            driver.handle_bytes(b, now);
            drain();
        };
        p.transmit = [this]() -> std::optional<std::vector<std::uint8_t>> {
            if (!also_sent.empty()) {  // a ground station's frames, sharing the port between ours
                auto frame = std::move(also_sent.front());
                also_sent.pop_front();
                return frame;
            }
            return driver.poll_transmit();
        };
        p.on_timeout = [this](TimePoint now) {
            driver.handle_timeout(now);
            drain();
        };
        p.deadline = [this] { return driver.poll_timeout(); };
        return p;
    }
    Party board() {
        Party p;
        p.receive = [this](std::span<const std::uint8_t> b, TimePoint now) { sim.handle_bytes(b, now); };
        // What the board has ready goes on the line in pieces of a UART's size, as a serial port delivers it:
        // the first of a long burst (the parameter list) arrives after its own air time, not after the whole
        // burst's.
        p.transmit = [this]() -> std::optional<std::vector<std::uint8_t>> {
            if (board_pending.empty()) {
                auto bytes = sim.poll_transmit();
                board_pending.insert(board_pending.end(), bytes.begin(), bytes.end());
            }
            if (board_pending.empty()) {
                return std::nullopt;
            }
            const auto n = std::min(board_pending.size(), kBoardChunk);
            std::vector<std::uint8_t> piece(board_pending.begin(),
                                            board_pending.begin() + static_cast<std::ptrdiff_t>(n));
            board_pending.erase(board_pending.begin(),
                                board_pending.begin() + static_cast<std::ptrdiff_t>(n));
            return piece;
        };
        p.on_timeout = [this](TimePoint now) { sim.handle_timeout(now); };
        p.deadline = [this] { return sim.poll_timeout(); };
        return p;
    }
    void drain() {
        while (auto e = driver.poll_event()) {
            events.push_back(std::move(*e));
        }
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
    RequestDone wait_result(std::uint32_t id, Duration limit = seconds(120)) {
        std::optional<RequestDone> found;
        harness.run_until(
            [&] {
                for (const auto& d : all<RequestDone>()) {
                    if (d.id == id) {
                        found = d;
                    }
                }
                return found.has_value();
            },
            now() + limit);
        return found ? *found
                     : RequestDone{
                           id, RequestKind::SetState, RequestResult::Cancelled, "no result", {}, {}, {}, {},
                           {}};
    }
    /// The port opens: the board sees DTR (and reboots when it is an APM on USB).
    bool open_and_wait_ready() {
        sim.port_opened(now());
        driver.on_port_open(now());
        return run_until_event<Ready>(1, seconds(60));
    }

    Driver driver;
    apmsim::RoverSim sim;
    Harness harness;
    std::vector<Event> events;
    std::deque<std::vector<std::uint8_t>> also_sent;
    static constexpr std::size_t kBoardChunk = 64;  // a 16550-style UART FIFO
    std::vector<std::uint8_t> board_pending;
};

std::vector<MissionItem> square(std::size_t n, double step_deg = 2e-4) {
    std::vector<MissionItem> items;
    for (std::size_t i = 0; i < n; ++i) {
        MissionItem it;
        it.lat = 41.2756 + step_deg * static_cast<double>((i + 1) % 4 < 2 ? 1 : 0);
        it.lon = 1.9866 + step_deg * static_cast<double>((i + 1) % 4 >= 1 && (i + 1) % 4 <= 2 ? 1 : 0);
        items.push_back(it);
    }
    return items;
}

TEST(DriverWithApmSim, ReadyWithinBootDelayCalibrationAndOneSecond) {
    for (const Board board : {Board::Apm2, Board::Pixhawk}) {
        SCOPED_TRACE(to_string(board));
        SimRig rig(board);
        const TimePoint opened = rig.now();
        ASSERT_TRUE(rig.open_and_wait_ready()) << rig.driver.last_error();
        const auto& sc = rig.sim.config();
        // The parameter list takes most of the last second: on a current board the banner texts come before
        // it, and the board's output reaches the port in 64-byte pieces.
        const Duration download = seconds(1) + milliseconds(250);
        const Duration budget =
            (board == Board::Apm2 ? sc.boot_delay + sc.calib_time : Duration{}) + download;
        EXPECT_LE(rig.now() - opened,
                  board == Board::Apm2 ? budget : sc.boot_delay + sc.calib_time + download);
        EXPECT_EQ(rig.driver.params().table().size(), rig.sim.params().size());
        // The board starts in its INITIAL_MODE, MANUAL: the RC pilot drives.
        EXPECT_EQ(rig.driver.status().state, VehicleState::Directed) << rig.driver.status().mode;
        ASSERT_TRUE(rig.driver.telemetry().home);
        EXPECT_NEAR(rig.driver.telemetry().home->lat, sc.home.lat, 1e-6);
    }
}

TEST(DriverWithApmSim, EachVehicleStateRequestedAndConfirmed) {
    for (const Board board : {Board::Apm2, Board::Pixhawk}) {
        SCOPED_TRACE(to_string(board));
        SimRig rig(board);
        ASSERT_TRUE(rig.open_and_wait_ready());
        ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(square(4), rig.now())).result, RequestResult::Ok);
        struct Step {
            VehicleState state;
            apmsim::RoverMode mode;
        };
        for (const Step s : {Step{VehicleState::WaypointNavigation, apmsim::RoverMode::Auto},
                             Step{VehicleState::Parking, apmsim::RoverMode::Hold},
                             Step{VehicleState::Directed, apmsim::RoverMode::Manual},
                             Step{VehicleState::ManualNavigation, apmsim::RoverMode::Manual},
                             Step{VehicleState::Manual, apmsim::RoverMode::Manual}}) {
            const auto r = rig.wait_result(rig.driver.request_state(s.state, rig.now()));
            EXPECT_EQ(r.result, RequestResult::Ok) << to_string(s.state) << ": " << r.detail;
            EXPECT_EQ(rig.driver.status().state, s.state);
            EXPECT_EQ(rig.sim.state().mode, s.mode);
        }
    }
}

// Boards other than APM 2.x get per-message rates with MAV_CMD_SET_MESSAGE_INTERVAL (the rate of 0 stops a
// message); APM 2.x gets REQUEST_DATA_STREAM groups.
TEST(DriverWithApmSim, MessageRatesAreSetWithSetMessageIntervalOnPixhawkBoards) {
    auto config = driver_config(Board::Pixhawk);
    config.message_rates = {{mav::Attitude::kId, 10.0}, {mav::GlobalPositionInt::kId, 0.0}, {1, 2.0}};
    SimRig rig(config, sim_config(Board::Pixhawk), {}, {}, 9);
    std::map<std::uint32_t, int> counts;
    bool counting = false;
    rig.driver.set_frame_tap([&](bool outgoing, std::span<const std::uint8_t> frame) {
        if (!outgoing && counting && frame.size() > 9 && frame[0] == 0xFD) {
            ++counts[frame[7] | (frame[8] << 8) | (frame[9] << 16)];
        }
    });
    ASSERT_TRUE(rig.open_and_wait_ready());
    rig.harness.run_for(seconds(2));  // the requests have taken effect
    counting = true;
    rig.harness.run_for(seconds(10));
    EXPECT_NEAR(counts[mav::Attitude::kId], 100, 3);
    EXPECT_EQ(counts[mav::GlobalPositionInt::kId], 0);
    EXPECT_NEAR(counts[1], 20, 2);  // SYS_STATUS
    EXPECT_NEAR(counts[mav::Heartbeat::kId], 10, 1);
}

TEST(DriverWithApmSim, ModeChangeByTheSimulatedRcPilotIsSeen) {
    SimRig rig(Board::Apm2);
    ASSERT_TRUE(rig.open_and_wait_ready());
    ASSERT_TRUE(rig.sim.rc_pilot(apmsim::RoverMode::Manual, rig.now()));
    rig.harness.run_for(seconds(2));
    const auto changes = rig.all<ModeChanged>();
    ASSERT_FALSE(changes.empty());
    EXPECT_EQ(changes.back().to, VehicleState::Directed);
    EXPECT_EQ(changes.back().cause, ModeChangeCause::External);
    EXPECT_EQ(rig.driver.status().mode, "MANUAL");
}

TEST(DriverWithApmSim, Upload150ItemsOverALossyLinkVerifiedByDownload) {
    // Ten percent of the frames to the board are lost, and the board's serial line loses one byte in a
    // hundred both ways (about a third of the mission items).
    LinkModel up;
    up.baud = 57600;
    up.latency = milliseconds(20);
    up.frame_drop = 0.10;
    LinkModel down = up;
    down.frame_drop = 0;
    SimRig rig(driver_config(Board::Pixhawk), sim_config(Board::Pixhawk), up, down, 21);
    ASSERT_TRUE(rig.open_and_wait_ready()) << rig.driver.last_error();
    rig.sim.faults().loss = 0.01;
    const auto items = square(150);
    const auto r = rig.wait_result(rig.driver.upload_mission(items, rig.now()), seconds(900));
    const auto& st = rig.driver.mission_client().stats();
    ASSERT_EQ(r.result, RequestResult::Ok)
        << r.detail << " restarts " << st.restarts << " retransmissions " << st.retransmissions << " srtt "
        << (rig.driver.mission_client().smoothed_rtt()
                ? rig.driver.mission_client().smoothed_rtt()->count() / 1e6
                : -1.0)
        << " ms, t " << (rig.now() - kStart).count() / 1e9 << " s, down bytes "
        << rig.sim.counters().bytes_out << " mstats rx " << rig.sim.mission_stats().items_received;
    ASSERT_EQ(rig.sim.mission().count(), 151u);
    const auto down_r = rig.wait_result(rig.driver.download_mission(rig.now()), seconds(900));
    ASSERT_EQ(down_r.result, RequestResult::Ok)
        << down_r.detail << " ignored " << st.ignored_frames << " sent by sim "
        << rig.sim.mission_stats().items_sent << " parser bad " << rig.driver.parser_stats().bad_checksum
        << " ok " << rig.driver.parser_stats().frames_ok << " link " << rig.driver.link_up()
        << " sim frames in " << rig.sim.counters().frames_in << " ignored "
        << rig.sim.counters().frames_ignored << " bytes in " << rig.sim.counters().bytes_in << " sent "
        << rig.harness.to_vehicle().frames() << " dropped " << rig.harness.to_vehicle().dropped_frames();
    ASSERT_EQ(down_r.items.size(), 150u);
    for (std::size_t i = 0; i < items.size(); ++i) {
        EXPECT_NEAR(down_r.items[i].lat, items[i].lat, 1e-7) << i;
        EXPECT_NEAR(down_r.items[i].lon, items[i].lon, 1e-7) << i;
    }
    EXPECT_GT(rig.sim.counters().bytes_lost, 0u);
    EXPECT_GT(rig.driver.mission_client().stats().retransmissions, 0u);
}

struct LossCase {
    Board board;
    double loss;
    double burst;
    std::uint32_t seed;
};

// The board's serial line loses `loss` of its bytes both ways (in bursts of `burst` bytes on average): the
// upload of a full APM 2.x mission completes, slower as the loss grows, and the download returns it.
void upload_and_verify_under_loss(const LossCase& c) {
    LinkModel radio;
    radio.baud = 57600;
    radio.latency = milliseconds(20);
    SimRig rig(driver_config(c.board), sim_config(c.board), radio, radio, c.seed);
    ASSERT_TRUE(rig.open_and_wait_ready()) << rig.driver.last_error();
    rig.sim.faults().loss = c.loss;
    rig.sim.faults().loss_burst = c.burst;
    const auto items = square(150);
    const TimePoint start = rig.now();
    const auto r = rig.wait_result(rig.driver.upload_mission(items, rig.now()), seconds(3600));
    const auto& st = rig.driver.mission_client().stats();
    const auto& ps = rig.driver.parser_stats();
    const auto srtt = rig.driver.mission_client().smoothed_rtt();
    std::cout << to_string(c.board) << " loss " << c.loss << " burst " << c.burst << ": upload "
              << to_string(r.result) << " in " << std::chrono::duration<double>(rig.now() - start).count()
              << " s, retransmissions " << st.retransmissions << " duplicates " << st.duplicate_requests
              << " restarts " << st.restarts << " srtt " << (srtt ? srtt->count() / 1e6 : -1.0)
              << " ms, sim cancelled " << rig.sim.mission_stats().uploads_cancelled << ", parser ok "
              << ps.frames_ok << " bad " << ps.bad_checksum << " truncated " << ps.truncated << " base "
              << rig.driver.mission_client().base_timeout().count() / 1e6 << " ms; " << r.detail << "\n";
    ASSERT_EQ(r.result, RequestResult::Ok) << r.detail;
    const TimePoint down_start = rig.now();
    const auto d = rig.wait_result(rig.driver.download_mission(rig.now()), seconds(3600));
    std::cout << "  download " << to_string(d.result) << " in "
              << std::chrono::duration<double>(rig.now() - down_start).count() << " s\n";
    ASSERT_EQ(d.result, RequestResult::Ok) << d.detail;
    ASSERT_EQ(d.items.size(), items.size());
    // APM 2.x items travel as float degrees: about 2e-6 degree of rounding at these latitudes.
    const double tolerance = c.board == Board::Apm2 ? 5e-6 : 1e-7;
    for (std::size_t i = 0; i < items.size(); ++i) {
        EXPECT_NEAR(d.items[i].lat, items[i].lat, tolerance) << i;
        EXPECT_NEAR(d.items[i].lon, items[i].lon, tolerance) << i;
    }
    const double lost = static_cast<double>(rig.sim.counters().bytes_lost);
    const double total = static_cast<double>(rig.sim.counters().bytes_in + rig.sim.counters().bytes_out);
    EXPECT_NEAR(lost / total, c.loss, c.loss * 0.25);
}

// Independent byte loss is the harshest case for MAVLink: at 3 % a 50-byte item frame arrives whole only one
// time in five. The upload gets slower (restarts when the board abandons it after 8 s), never stuck.
TEST(DriverWithApmSim, UploadUnderRandomByteLoss) {
    for (const double loss : {0.02, 0.03}) {
        for (const Board board : {Board::Apm2, Board::Pixhawk}) {
            SCOPED_TRACE(std::string(to_string(board)) + " loss " + std::to_string(loss));
            upload_and_verify_under_loss({board, loss, 1.0, 11});
        }
    }
}

// The acceptance case: the board loses a tenth of the bytes it would send and receive, in bursts (a radio
// fade): frames cut short, the tail of one and the head of the next, whole frames.
TEST(DriverWithApmSim, UploadWithTenPercentOfBytesLostInBursts) {
    for (const Board board : {Board::Apm2, Board::Pixhawk}) {
        SCOPED_TRACE(to_string(board));
        upload_and_verify_under_loss({board, 0.10, 32.0, 17});
    }
}

TEST(DriverWithApmSim, DrivesTheMissionAndReportsReachedWaypoints) {
    for (const Board board : {Board::Apm2, Board::Pixhawk}) {
        SCOPED_TRACE(to_string(board));
        SimRig rig(board);
        ASSERT_TRUE(rig.open_and_wait_ready());
        ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(square(4), rig.now())).result, RequestResult::Ok);
        ASSERT_EQ(
            rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
            RequestResult::Ok);
        ASSERT_TRUE(rig.run_until_event<WaypointReached>(4, seconds(600)));
        const auto reached = rig.all<WaypointReached>();
        for (std::size_t i = 0; i < 4; ++i) {
            EXPECT_EQ(reached[i].seq, i + 1);
        }
        EXPECT_EQ(rig.sim.reached().size(), 4u);  // one event per reach, not two
        // The mission ends in HOLD, by the autopilot's own decision.
        rig.harness.run_for(seconds(5));
        EXPECT_EQ(rig.driver.status().state, VehicleState::Parking);
        EXPECT_EQ(rig.all<ModeChanged>().back().cause, ModeChangeCause::External);
    }
}

TEST(DriverWithApmSim, RebootMidMissionIsDetectedAndResynced) {
    SimRig rig(Board::Apm2);
    ASSERT_TRUE(rig.open_and_wait_ready());
    ASSERT_EQ(rig.wait_result(rig.driver.upload_mission(square(8), rig.now())).result, RequestResult::Ok);
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::WaypointNavigation, rig.now())).result,
              RequestResult::Ok);
    ASSERT_TRUE(rig.run_until_event<WaypointReached>(1, seconds(300)));
    rig.sim.schedule_reboot(rig.now() + seconds(1));
    ASSERT_TRUE(rig.run_until_event<AutopilotRebooted>(1, seconds(30)));
    ASSERT_TRUE(rig.run_until_event<Ready>(2, seconds(60))) << rig.driver.last_error();
    EXPECT_EQ(rig.driver.status().reboots, 1u);
    EXPECT_EQ(rig.driver.mission().size(), rig.sim.mission().count() - 1);
    EXPECT_TRUE(rig.driver.ready());
}

TEST(DriverWithApmSim, TenSecondHeartbeatStallIsDetectedAndRecovered) {
    SimRig rig(Board::Apm2);
    ASSERT_TRUE(rig.open_and_wait_ready());
    const TimePoint stall = rig.now();
    EXPECT_TRUE(rig.sim.long_heartbeat_gaps().empty());
    EXPECT_LE(rig.sim.counters().heartbeat_gap_max, seconds(1) + milliseconds(20));
    rig.sim.stall_heartbeats(seconds(10), rig.now());
    ASSERT_TRUE(rig.run_until_event<LinkDown>(1, seconds(10)));
    EXPECT_LE(rig.now() - stall, seconds(4));
    // The board streams on without beating: the verdict says the port carried its frames.
    const std::string reason = rig.all<LinkDown>()[0].reason;
    EXPECT_TRUE(reason.starts_with("no heartbeat for 3 s (")) << reason;
    EXPECT_NE(reason.find(" of the autopilot's frames among them, the last bytes 0."), std::string::npos)
        << reason;
    ASSERT_TRUE(rig.run_until_event<LinkUp>(2, seconds(15)));
    EXPECT_GE(rig.now() - stall, seconds(9));
    EXPECT_TRUE(rig.driver.ready());
    EXPECT_EQ(rig.driver.status().reboots, 0u);
    EXPECT_EQ(rig.driver.status().state, VehicleState::Directed);
    // The simulator keeps the silence it made: one gap of the stall's length, the longest.
    ASSERT_EQ(rig.sim.long_heartbeat_gaps().size(), 1u);
    const apmsim::HeartbeatGap gap = rig.sim.long_heartbeat_gaps().front();
    EXPECT_GE(gap.length, seconds(10));
    EXPECT_LE(gap.length, seconds(11));
    EXPECT_EQ(rig.sim.counters().heartbeat_gap_max, gap.length);
}

TEST(DriverWithApmSim, RcOverrideDrivesAndIsReleasedWhenTheJoystickStops) {
    auto config = driver_config(Board::Apm2);
    config.rc_override.input_timeout = milliseconds(500);
    SimRig rig(config, sim_config(Board::Apm2), {}, {}, 3);
    ASSERT_TRUE(rig.open_and_wait_ready());
    ASSERT_EQ(rig.wait_result(rig.driver.request_state(VehicleState::ManualNavigation, rig.now())).result,
              RequestResult::Ok);
    for (int i = 0; i < 25; ++i) {
        rig.driver.joystick(0.0, 0.8, rig.now());
        rig.harness.run_for(milliseconds(200));
    }
    const double driving_speed = rig.sim.state().speed;
    EXPECT_GT(driving_speed, 0.5);
    // The ground link is lost: no more input. The board's own override timeout is 3 s; ours releases first,
    // and the car starts slowing down within the input timeout (plus a physics step and a link transit).
    const TimePoint last_input = rig.now() - milliseconds(200);
    std::optional<Duration> slowing_after;
    for (int i = 0; i < 60 && !slowing_after; ++i) {
        rig.harness.run_for(milliseconds(50));
        if (rig.sim.state().speed < driving_speed - 0.05) {
            slowing_after = rig.now() - last_input;
        }
    }
    ASSERT_TRUE(slowing_after) << "still driving on a stale command";
    EXPECT_LE(*slowing_after, config.rc_override.input_timeout + milliseconds(150));
    EXPECT_EQ(rig.driver.rc_override().releases(), 1u);
    rig.harness.run_for(seconds(10));
    EXPECT_EQ(rig.sim.state().speed, 0.0);
}

TEST(DriverWithApmSim, TheBoardAnswersASecondGroundStationByItsSystemId) {
    // A ground station (system 254) sharing airsegd's port to the autopilot reads the mission and a
    // parameter and sends a command; the board answers it, not airsegd, and airsegd stays ready.
    SimRig rig(Board::Pixhawk);
    ASSERT_TRUE(rig.open_and_wait_ready());
    std::vector<mav::Frame> heard;
    rig.driver.set_frame_tap([&](bool outgoing, std::span<const std::uint8_t> bytes) {
        if (!outgoing) {
            mav::Parser p;
            p.push(bytes, [&](const mav::Frame& f) { heard.push_back(f); });
        }
    });
    mav::Encoder gcs(254, 190);
    mav::MissionRequestList list;
    list.target_system = 1;
    list.target_component = 1;
    mav::ParamRequestRead read;
    read.target_system = 1;
    read.target_component = 1;
    read.param_index = -1;
    mav::set_text(read.param_id, "CRUISE_SPEED");
    mav::CommandLong cmd;
    cmd.target_system = 1;
    cmd.target_component = 1;
    cmd.command = 31000;  // no such command: answered as unsupported
    rig.also_sent = {gcs.encode(list), gcs.encode(read), gcs.encode(cmd)};
    auto addressed_to_254 = [&](std::uint32_t msgid) {
        for (const auto& f : heard) {
            if (f.msgid != msgid) {
                continue;
            }
            if (msgid == mav::MissionCount::kId &&
                mav::decode_payload<mav::MissionCount>(f.payload_view()).target_system == 254) {
                return true;
            }
            if (msgid == mav::CommandAck::kId &&
                mav::decode_payload<mav::CommandAck>(f.payload_view()).target_system == 254) {
                return true;
            }
            if (msgid == mav::ParamValue::kId &&
                mav::text_of(mav::decode_payload<mav::ParamValue>(f.payload_view()).param_id) ==
                    "CRUISE_SPEED") {
                return true;
            }
        }
        return false;
    };
    EXPECT_TRUE(rig.harness.run_until(
        [&] {
            return addressed_to_254(mav::MissionCount::kId) && addressed_to_254(mav::CommandAck::kId) &&
                   addressed_to_254(mav::ParamValue::kId);
        },
        rig.now() + seconds(5)))
        << "mission count " << addressed_to_254(mav::MissionCount::kId) << ", command ack "
        << addressed_to_254(mav::CommandAck::kId) << ", parameter " << addressed_to_254(mav::ParamValue::kId);
    rig.harness.run_for(seconds(2));
    EXPECT_TRUE(rig.driver.ready());
    EXPECT_TRUE(rig.all<AutopilotRebooted>().empty());
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot
