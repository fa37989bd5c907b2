// The real airseg-apmsim binary on its pseudo-terminal, driven the way a ground station drives an APM:
// open the port (the board reboots), list the parameters, upload a mission, switch to AUTO, follow the
// reached events to HOLD. Simulated time runs faster than real time (--speedup); every wait is on a
// condition with a generous deadline.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "tests/integration/apmsim/gcs_link.hpp"
#include "tests/support/process.hpp"

namespace airseg::apmsim::test {
namespace {

using namespace std::chrono_literals;
using airseg::test::Subprocess;
using airseg::test::TempDir;
using airseg::test::wait_until;

constexpr auto kGenerous = 20s;
constexpr double kHomeLat = 41.2756;
constexpr double kHomeLon = 1.9866;

bool exists(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0;
}

std::vector<std::string> sim_argv(const TempDir& dir, std::vector<std::string> extra) {
    std::vector<std::string> argv{airseg::test::binary("tools/apmsim/airseg-apmsim"),
                                  "--link",
                                  dir.file("ttyACM0"),
                                  "--control",
                                  dir.file("ctl"),
                                  "--home",
                                  "41.2756,1.9866"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return argv;
}

nlohmann::json ask_json(ControlClient& ctl, const std::string& command) {
    const auto reply = ctl.command(command);
    if (!reply) {
        ADD_FAILURE() << "no reply to " << command;
        return {};
    }
    return nlohmann::json::parse(*reply);
}

mv::MissionItemInt item_at(std::uint16_t seq, double north_m) {
    mv::MissionItemInt m;
    m.target_system = 1;
    m.target_component = 1;
    m.seq = seq;
    m.frame = 3;
    m.command = 16;
    m.autocontinue = 1;
    m.x = static_cast<std::int32_t>(std::lround((kHomeLat + north_m / 111319.49) * 1e7));
    m.y = static_cast<std::int32_t>(std::lround(kHomeLon * 1e7));
    return m;
}

bool is_heartbeat(const mv::Frame& f, std::uint32_t custom_mode) {
    auto hb = mv::decode<mv::Heartbeat>(f);
    return hb && hb->custom_mode == custom_mode;
}

TEST(ApmsimBinary, GroundStationSessionUploadsHundredItemsAndDrivesThemToHold) {
    TempDir dir;
    Subprocess sim(sim_argv(dir, {"--speedup", "20", "--param", "CRUISE_SPEED=10", "--param", "WP_RADIUS=2"}),
                   {}, dir.path());
    ASSERT_TRUE(wait_until([&] { return exists(dir.file("ttyACM0")) && exists(dir.file("ctl")); }, kGenerous))
        << sim.err();
    ControlClient ctl(dir.file("me"), dir.file("ctl"));
    // Let the power-on boot finish, so that what follows the open can only be a reboot.
    ASSERT_TRUE(wait_until([&] { return ask_json(ctl, "state")["phase"] == "ready"; }, kGenerous));
    EXPECT_EQ(ask_json(ctl, "state")["boots"], 1);

    GcsLink gcs;
    ASSERT_TRUE(gcs.open(dir.file("ttyACM0")));

    // The reboot on open: boot silence, then "Initialising APM..." and heartbeats in BOOT/CALIBRATING.
    std::size_t first = 0;
    ASSERT_TRUE(gcs.wait_frame([](const mv::Frame&) { return true; }, kGenerous, 0));
    const auto init = gcs.wait_for<mv::Statustext>(
        [](const mv::Statustext& t) { return mv::text_of(t.text) == "Initialising APM..."; }, kGenerous, 0,
        &first);
    ASSERT_TRUE(init);
    EXPECT_EQ(first, 0u) << "the first thing after the open is the boot banner";
    // 2 s of silence at speedup 20 is 100 ms of real time.
    EXPECT_GE(gcs.heard[0].at - gcs.opened_at(), 80ms);
    auto hb = gcs.wait_for<mv::Heartbeat>(kGenerous, 0);
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->system_status, 2) << "MAV_STATE_CALIBRATING while initialising";
    EXPECT_EQ(hb->custom_mode, 16u);
    EXPECT_EQ(ask_json(ctl, "state")["boots"], 2);
    ASSERT_TRUE(gcs.wait_for<mv::Statustext>(
        [](const mv::Statustext& t) { return mv::text_of(t.text) == "Ready to drive."; }, kGenerous, 0));
    hb = gcs.wait_for<mv::Heartbeat>([](const mv::Heartbeat& h) { return h.system_status >= 3; }, kGenerous,
                                     0);
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->custom_mode, 0u) << "MANUAL";
    EXPECT_FALSE(hb->base_mode & 128) << "disarmed: ARMING_REQUIRE 1";
    mv::CommandLong arm;
    arm.command = 400;  // MAV_CMD_COMPONENT_ARM_DISARM
    arm.param1 = 1;
    std::size_t arm_from = gcs.heard.size();
    ASSERT_TRUE(gcs.send(arm));
    const auto armed = gcs.wait_for<mv::CommandAck>([](const mv::CommandAck& a) { return a.command == 400; },
                                                    kGenerous, arm_from);
    ASSERT_TRUE(armed);
    EXPECT_EQ(armed->result, 0);
    ASSERT_TRUE(gcs.wait_for<mv::Heartbeat>([](const mv::Heartbeat& h) { return (h.base_mode & 128) != 0; },
                                            kGenerous, arm_from));

    // Parameters: the whole list, then one set with its echo.
    std::size_t from = gcs.heard.size();
    ASSERT_TRUE(gcs.send(mv::ParamRequestList{}));
    std::set<std::uint16_t> indexes;
    std::set<std::string> names;
    std::uint16_t total = 0;
    ASSERT_TRUE(gcs.wait_for<mv::ParamValue>(
        [&](const mv::ParamValue& v) {
            indexes.insert(v.param_index);
            names.insert(std::string(mv::text_of(v.param_id)));
            total = v.param_count;
            return indexes.size() == total;
        },
        kGenerous, from));
    EXPECT_GE(total, 200);
    EXPECT_TRUE(names.count("WP_RADIUS"));
    EXPECT_TRUE(names.count("CRUISE_SPEED"));
    mv::ParamSet set;
    mv::set_text(set.param_id, "WP_RADIUS");
    set.param_value = 2.5F;
    set.param_type = 9;
    from = gcs.heard.size();
    ASSERT_TRUE(gcs.send(set));
    const auto echo = gcs.wait_for<mv::ParamValue>(
        [](const mv::ParamValue& v) { return mv::text_of(v.param_id) == "WP_RADIUS"; }, kGenerous, from);
    ASSERT_TRUE(echo);
    EXPECT_FLOAT_EQ(echo->param_value, 2.5F);

    // Upload home + 100 waypoints, 5 m apart northwards, answering each MISSION_REQUEST.
    constexpr std::uint16_t kItems = 100;
    mv::MissionCount count;
    count.count = kItems + 1;
    from = gcs.heard.size();
    ASSERT_TRUE(gcs.send(count));
    std::optional<std::uint8_t> result;
    std::size_t scan = from;
    while (!result) {
        const auto i = gcs.wait_frame(
            [](const mv::Frame& f) {
                return f.msgid == mv::MissionRequest::kId || f.msgid == mv::MissionRequestInt::kId ||
                       f.msgid == mv::MissionAck::kId;
            },
            kGenerous, scan);
        ASSERT_TRUE(i) << "the upload stalled";
        scan = *i + 1;
        const mv::Frame& f = gcs.heard[*i].frame;
        if (auto ack = mv::decode<mv::MissionAck>(f)) {
            if (ack->type != 13) {  // INVALID_SEQUENCE answers a duplicate; the transfer goes on
                result = ack->type;
            }
            continue;
        }
        const std::uint16_t seq = f.msgid == mv::MissionRequest::kId
                                      ? mv::decode<mv::MissionRequest>(f)->seq
                                      : mv::decode<mv::MissionRequestInt>(f)->seq;
        ASSERT_LE(seq, kItems);
        ASSERT_TRUE(gcs.send(item_at(seq, 5.0 * seq)));
    }
    ASSERT_EQ(*result, 0) << "MISSION_ACK ACCEPTED";
    EXPECT_EQ(ask_json(ctl, "state")["mission_count"], kItems + 1);

    // AUTO: the rover drives the items in order and holds after the last one.
    mv::CommandLong auto_mode;
    auto_mode.command = 176;
    auto_mode.param1 = 1;   // MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
    auto_mode.param2 = 10;  // AUTO
    from = gcs.heard.size();
    ASSERT_TRUE(gcs.send(auto_mode));
    const auto ack = gcs.wait_for<mv::CommandAck>([](const mv::CommandAck& a) { return a.command == 176; },
                                                  kGenerous, from);
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->result, 0);
    ASSERT_TRUE(gcs.wait_frame([](const mv::Frame& f) { return is_heartbeat(f, 10); }, kGenerous, from));
    std::size_t hold_at = 0;
    ASSERT_TRUE(gcs.wait_frame([](const mv::Frame& f) { return is_heartbeat(f, 4); }, 60s, from).has_value());
    hold_at = *gcs.wait_frame([](const mv::Frame& f) { return is_heartbeat(f, 4); }, 1s, from);

    std::vector<std::uint16_t> reached;
    for (const auto& r : gcs.all<mv::MissionItemReached>(from)) {
        reached.push_back(r.seq);
    }
    std::vector<std::uint16_t> expected(kItems);
    for (std::uint16_t i = 0; i < kItems; ++i) {
        expected[i] = static_cast<std::uint16_t>(i + 1);
    }
    EXPECT_EQ(reached, expected);
    int texts = 0;
    for (const auto& t : gcs.all<mv::Statustext>(from)) {
        texts += mv::text_of(t.text).rfind("Reached waypoint #", 0) == 0 ? 1 : 0;
    }
    EXPECT_EQ(texts, kItems);
    // The last reached event comes before the first HOLD heartbeat.
    std::size_t last_reached = 0;
    for (std::size_t i = from; i < gcs.heard.size(); ++i) {
        if (gcs.heard[i].frame.msgid == mv::MissionItemReached::kId) {
            last_reached = i;
        }
    }
    EXPECT_LT(last_reached, hold_at);

    // The mode history: AUTO by command, HOLD only at the mission's end.
    const auto modes = ask_json(ctl, "modes");
    ASSERT_FALSE(modes.empty());
    EXPECT_EQ(modes.back()["to"], "HOLD");
    EXPECT_EQ(modes.back()["cause"], "mission end");
    EXPECT_EQ(modes[modes.size() - 2]["to"], "AUTO");
    EXPECT_EQ(modes[modes.size() - 2]["cause"], "command");

    gcs.close();
    sim.signal(SIGTERM);
    ASSERT_EQ(sim.wait_exit(kGenerous), 0) << sim.err();
    const auto summary = nlohmann::json::parse(sim.out());
    EXPECT_EQ(summary["modes"].back()["cause"], "mission end");
    EXPECT_EQ(summary["state"]["reached"], kItems);
}

TEST(ApmsimBinary, NoResetOnOpenAndMavlinkOne) {
    TempDir dir;
    Subprocess sim(sim_argv(dir, {"--speedup", "20", "--no-reset-on-open", "--mavlink1"}), {}, dir.path());
    ASSERT_TRUE(
        wait_until([&] { return exists(dir.file("ttyACM0")) && exists(dir.file("ctl")); }, kGenerous));
    ControlClient ctl(dir.file("me"), dir.file("ctl"));
    ASSERT_TRUE(wait_until([&] { return ask_json(ctl, "state")["phase"] == "ready"; }, kGenerous));
    GcsLink gcs;
    ASSERT_TRUE(gcs.open(dir.file("ttyACM0")));
    const auto hb = gcs.wait_for<mv::Heartbeat>(kGenerous, 0);
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->system_status, 4) << "still running: no reboot";
    EXPECT_EQ(gcs.heard.front().frame.version, mv::Version::V1);
    EXPECT_EQ(ask_json(ctl, "state")["boots"], 1);
}

TEST(ApmsimBinary, UnplugReplugAndRunTimeFaults) {
    TempDir dir;
    Subprocess sim(sim_argv(dir, {"--speedup", "20"}), {}, dir.path());
    ASSERT_TRUE(
        wait_until([&] { return exists(dir.file("ttyACM0")) && exists(dir.file("ctl")); }, kGenerous));
    ControlClient ctl(dir.file("me"), dir.file("ctl"));
    GcsLink gcs;
    ASSERT_TRUE(gcs.open(dir.file("ttyACM0")));
    ASSERT_TRUE(gcs.wait_for<mv::Statustext>(
        [](const mv::Statustext& t) { return mv::text_of(t.text) == "Ready to drive."; }, kGenerous, 0));

    EXPECT_EQ(ctl.command("rcpilot HOLD").value_or(""), "ok mode HOLD\n");
    ASSERT_TRUE(gcs.wait_frame([](const mv::Frame& f) { return is_heartbeat(f, 4); }, kGenerous, 0));
    EXPECT_EQ(ask_json(ctl, "modes").back()["cause"], "rc pilot");
    EXPECT_EQ(ctl.command("hbstall nope").value_or("").rfind("error: ", 0), 0u);
    EXPECT_EQ(ctl.command("frobnicate").value_or("").rfind("error: unknown command", 0), 0u);

    EXPECT_EQ(ctl.command("unplug").value_or("").rfind("ok", 0), 0u);
    EXPECT_TRUE(wait_until([&] { return !gcs.pump(10ms); }, kGenerous)) << "the open port ends";
    EXPECT_FALSE(exists(dir.file("ttyACM0")));
    gcs.close();
    EXPECT_EQ(ctl.command("replug").value_or("").rfind("ok", 0), 0u);
    ASSERT_TRUE(wait_until([&] { return exists(dir.file("ttyACM0")); }, kGenerous));
    GcsLink again;
    ASSERT_TRUE(again.open(dir.file("ttyACM0")));
    ASSERT_TRUE(again.wait_for<mv::Statustext>(
        [](const mv::Statustext& t) { return mv::text_of(t.text) == "Initialising APM..."; }, kGenerous, 0))
        << "opening the new port resets the board";
    EXPECT_EQ(ask_json(ctl, "state")["boots"], 3);
}

TEST(ApmsimBinary, Rover2FirmwareOnThePty) {
    TempDir dir;
    Subprocess sim(sim_argv(dir, {"--speedup", "20", "--firmware", "rover2"}), {}, dir.path());
    ASSERT_TRUE(
        wait_until([&] { return exists(dir.file("ttyACM0")) && exists(dir.file("ctl")); }, kGenerous));
    ControlClient ctl(dir.file("me"), dir.file("ctl"));
    GcsLink gcs;
    ASSERT_TRUE(gcs.open(dir.file("ttyACM0")));
    ASSERT_TRUE(gcs.wait_for<mv::Statustext>(
        [](const mv::Statustext& t) { return mv::text_of(t.text) == "\n\n Ready to drive."; }, kGenerous, 0));
    for (const auto& h : gcs.heard) {
        EXPECT_EQ(h.frame.version, mv::Version::V1);
    }
    mv::ParamRequestRead q;
    q.param_index = -1;
    mv::set_text(q.param_id, "CRUISE_SPEED");
    ASSERT_TRUE(gcs.send(q));  // MAVLink 2: noise to this board
    ASSERT_TRUE(wait_until([&] { return ask_json(ctl, "stats")["mavlink2_ignored"] == 1; }, kGenerous));
    gcs.set_version(mv::Version::V1);
    const std::size_t from = gcs.heard.size();
    ASSERT_TRUE(gcs.send(q));
    ASSERT_TRUE(gcs.wait_for<mv::ParamValue>(kGenerous, from));

    EXPECT_EQ(ask_json(ctl, "state")["firmware"], "rover2");
    EXPECT_EQ(ctl.command("mode HOLD").value_or(""), "ok mode HOLD\n");
    ASSERT_TRUE(gcs.wait_frame([](const mv::Frame& f) { return is_heartbeat(f, 4); }, kGenerous, from));
    EXPECT_EQ(ask_json(ctl, "modes").back()["cause"], "board");
    const auto speeds = ask_json(ctl, "speeds");
    ASSERT_GE(speeds["speeds"].size(), 1u);
    EXPECT_EQ(speeds["speeds"][0]["cause"], "power on");
    EXPECT_EQ(speeds["speeds"][0]["speed"], 2.0);
}

TEST(ApmsimBinary, HelpAndBadOptions) {
    auto help = airseg::test::run({airseg::test::binary("tools/apmsim/airseg-apmsim"), "--help"});
    EXPECT_EQ(help.exit_code, 0);
    for (const char* option : {"--link",          "--boot-delay",
                               "--calib-time",    "--no-reset-on-open",
                               "--home",          "--mission-capacity",
                               "--reached-style", "--mavlink1",
                               "--seed",          "--speedup",
                               "--loss",          "--corrupt",
                               "--hb-stall",      "--reboot-at",
                               "--unplug",        "--ignore-mission",
                               "--slow",          "--control",
                               "rcpilot",         "modes",
                               "hbstall",         "ignore-mission",
                               "--loss-burst",    "--baud",
                               "--firmware",      "speeds",
                               "mode MODE"}) {
        EXPECT_NE(help.out.find(option), std::string::npos) << option;
    }
    auto bad = airseg::test::run(
        {airseg::test::binary("tools/apmsim/airseg-apmsim"), "--link", "/tmp/x", "--loss", "2"});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("--loss"), std::string::npos) << bad.err;
    auto unknown_param = airseg::test::run(
        {airseg::test::binary("tools/apmsim/airseg-apmsim"), "--link", "/tmp/x", "--param", "NOPE=1"});
    EXPECT_EQ(unknown_param.exit_code, 2);
    EXPECT_NE(unknown_param.err.find("NOPE"), std::string::npos);
}

}  // namespace
}  // namespace airseg::apmsim::test
