// What a hostile or broken autopilot (or ground station) sends, in simulated time: the parameter cache holds
// no more names than the autopilot announced, positions that name no place and NaNs never reach the
// telemetry, a STATUSTEXT of any bytes is escaped, and a mission upload cannot announce 65,535 items.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "services/autopilot/ardupilot/driver.hpp"
#include "services/autopilot/ardupilot/param_client.hpp"
#include "services/autopilot/ardupilot/telemetry_check.hpp"
#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "services/autopilot/mission_receiver.hpp"
#include "services/common/printable.hpp"

namespace airseg::autopilot::ardupilot {
namespace {

namespace mav = airseg::mavlink;

const TimePoint kInputStart = TimePoint{} + std::chrono::hours(3);

/// Frames from the autopilot (system 1, component 1) straight into a sans-IO core.
struct Board {
    mav::Encoder encoder{1, 1};

    template <class M, class Sink>
    void send(const M& m, Sink&& sink) {
        mav::Parser parser;
        parser.push(encoder.encode(m), [&](const mav::Frame& f) { sink(f); });
    }
};

mav::ParamValue param(const std::string& name, std::uint16_t count, std::uint16_t index, float value = 1.0f) {
    mav::ParamValue v;
    mav::set_text(v.param_id, name);
    v.param_count = count;
    v.param_index = index;
    v.param_value = value;
    v.param_type = 9;
    return v;
}

struct ParamRig {
    Outbox out{255, 190, mav::Version::V2};
    ParamClient client{out, 1, 1, ParamClientConfig{}};
    Board board;
    void feed(const mav::ParamValue& v) {
        board.send(v, [&](const mav::Frame& f) { client.handle_frame(f, kInputStart); });
    }
};

TEST(ParamCacheBound, AFloodOfNewNamesStopsAtTheCountTheAutopilotAnnounced) {
    ParamRig rig;
    for (std::uint16_t i = 0; i < 1200; ++i) {
        rig.feed(param("P" + std::to_string(i), 1200, i));
    }
    ASSERT_EQ(rig.client.table().size(), 1200u);
    // Then the same table's count with 100,000 names never seen: none is kept, each is counted.
    for (int i = 0; i < 100'000; ++i) {
        rig.feed(param("X" + std::to_string(i), 1200, 65535));
    }
    EXPECT_EQ(rig.client.table().size(), 1200u);
    EXPECT_EQ(rig.client.dropped(), 100'000u);
    EXPECT_TRUE(rig.client.cached("P17"));
    EXPECT_FALSE(rig.client.cached("X17"));
    // A known name still updates.
    rig.feed(param("P17", 1200, 17, 4.5f));
    EXPECT_EQ(rig.client.cached("P17"), 4.5f);
}

TEST(ParamCacheBound, WithoutAUsableCountTheCacheStopsAtTheDocumentedMaximum) {
    ParamRig rig;
    // param_count 0 and counts above the maximum announce nothing usable.
    for (int i = 0; i < 10'000; ++i) {
        rig.feed(param("N" + std::to_string(i), i % 2 == 0 ? 0 : 65000, 65535));
    }
    EXPECT_EQ(rig.client.table().size(), ParamClient::kMaxParams);
    EXPECT_EQ(rig.client.dropped(), 10'000u - ParamClient::kMaxParams);
}

TEST(ParamCacheBound, ANewCountIsANewTableAndReplacesTheOldNames) {
    ParamRig rig;
    for (std::uint16_t i = 0; i < 10; ++i) {
        rig.feed(param("OLD" + std::to_string(i), 10, i));
    }
    for (std::uint16_t i = 0; i < 12; ++i) {
        rig.feed(param("NEW" + std::to_string(i), 12, i));
    }
    EXPECT_EQ(rig.client.table().size(), 12u);
    EXPECT_FALSE(rig.client.cached("OLD3"));
    EXPECT_TRUE(rig.client.cached("NEW11"));
    EXPECT_EQ(rig.client.dropped(), 0u);
}

TEST(ParamCacheBound, NamesThatAreNotPrintableAsciiAreDroppedAndCounted) {
    ParamRig rig;
    rig.feed(param(std::string("BAD\xff") + "NAME", 5, 0));
    rig.feed(param("TAB\tNAME", 5, 1));
    rig.feed(param("GOOD_NAME", 5, 2));
    EXPECT_EQ(rig.client.table().size(), 1u);
    EXPECT_EQ(rig.client.dropped(), 2u);
}

TEST(ParamCacheBound, AGetOfANameTheFullCacheCannotHoldStillCompletes) {
    ParamRig rig;
    for (std::uint16_t i = 0; i < 3; ++i) {
        rig.feed(param("P" + std::to_string(i), 3, i));
    }
    const auto id = rig.client.get("EXTRA", kInputStart);
    rig.feed(param("EXTRA", 3, 65535, 7.0f));
    const auto done = rig.client.poll_completion();
    ASSERT_TRUE(done);
    EXPECT_EQ(done->id, id);
    EXPECT_EQ(done->result, RequestResult::Ok);
    EXPECT_EQ(done->value, 7.0f);
    EXPECT_EQ(rig.client.table().size(), 3u);
}

/// The driver with its port open, fed frames one by one.
struct DriverRig {
    Driver driver{AutopilotConfig::defaults_for(autopilot::Board::Apm2)};
    Board board;
    std::vector<Event> events;
    DriverRig() { driver.on_port_open(kInputStart); }
    template <class M>
    void feed(const M& m) {
        const auto bytes = board.encoder.encode(m);
        driver.handle_bytes(bytes, kInputStart);
        while (auto e = driver.poll_event()) {
            events.push_back(std::move(*e));
        }
    }
};

mav::GlobalPositionInt position(double lat, double lon) {
    mav::GlobalPositionInt p;
    p.lat = static_cast<std::int32_t>(std::lround(lat * 1e7));
    p.lon = static_cast<std::int32_t>(std::lround(lon * 1e7));
    p.alt = 12'000;
    p.hdg = 65535;
    return p;
}

TEST(TelemetryChecks, APositionOutsideTheGlobeIsInvalidNeverAPlace) {
    DriverRig rig;
    rig.feed(position(41.2756, 1.9866));
    ASSERT_TRUE(rig.driver.telemetry().position);
    rig.feed(position(199.17, 1.9866));
    EXPECT_FALSE(rig.driver.telemetry().position);
    EXPECT_EQ(rig.driver.telemetry().position_invalid, "latitude 199.1700000 outside ±90");
    auto s = rig.driver.status();
    EXPECT_FALSE(s.position);
    EXPECT_EQ(s.refused_values, 1u);
    EXPECT_EQ(s.refused_value, "GLOBAL_POSITION_INT: latitude 199.1700000 outside ±90");
    rig.feed(position(41.0, -181.5));
    EXPECT_EQ(rig.driver.telemetry().position_invalid, "longitude -181.5000000 outside ±180");
    // A valid one is a place again.
    rig.feed(position(41.2757, 1.9867));
    ASSERT_TRUE(rig.driver.telemetry().position);
    EXPECT_TRUE(rig.driver.telemetry().position_invalid.empty());
    EXPECT_DOUBLE_EQ(rig.driver.telemetry().position->lat, 41.2757);
}

TEST(TelemetryChecks, ZeroZeroAndNoFixAreNoPosition) {
    DriverRig rig;
    rig.feed(position(0, 0));
    EXPECT_FALSE(rig.driver.telemetry().position);
    EXPECT_EQ(rig.driver.telemetry().position_invalid, "latitude and longitude 0 (no fix yet)");
    EXPECT_EQ(rig.driver.status().refused_values, 0u) << "no fix is normal, not a refused value";

    mav::GpsRawInt gps;
    gps.fix_type = 1;
    gps.lat = 412'756'000;
    gps.lon = 19'866'000;
    rig.feed(gps);
    rig.feed(position(41.2756, 1.9866));  // the autopilot's estimate without a fix
    EXPECT_FALSE(rig.driver.telemetry().position);
    EXPECT_EQ(rig.driver.telemetry().position_invalid, "no GPS fix (GPS_RAW_INT fix_type 1)");

    gps.fix_type = 3;
    rig.feed(gps);
    ASSERT_TRUE(rig.driver.telemetry().position) << "GPS_RAW_INT with a fix gives the first position";
    gps.fix_type = 0;
    rig.feed(gps);
    EXPECT_FALSE(rig.driver.telemetry().position) << "losing the fix takes the place away";
}

TEST(TelemetryChecks, NaNAndInfiniteFloatsAreNotTaken) {
    DriverRig rig;
    mav::Attitude a;
    a.roll = 0.1f;
    a.pitch = 0.2f;
    a.yaw = 0.3f;
    rig.feed(a);
    a.roll = std::numeric_limits<float>::quiet_NaN();
    a.pitch = std::numeric_limits<float>::infinity();
    a.yaw = 0.5f;
    rig.feed(a);
    EXPECT_FLOAT_EQ(static_cast<float>(rig.driver.telemetry().roll), 0.1f);
    EXPECT_FLOAT_EQ(static_cast<float>(rig.driver.telemetry().pitch), 0.2f);
    EXPECT_FLOAT_EQ(static_cast<float>(rig.driver.telemetry().yaw), 0.5f);
    mav::VfrHud hud;
    hud.groundspeed = -std::numeric_limits<float>::infinity();
    rig.feed(hud);
    EXPECT_TRUE(std::isfinite(rig.driver.telemetry().ground_speed));
    EXPECT_EQ(rig.driver.status().refused_values, 3u);
    EXPECT_EQ(rig.driver.status().refused_value, "VFR_HUD.groundspeed is -inf");
}

TEST(TelemetryChecks, AHomeOutsideTheGlobeIsNotTaken) {
    DriverRig rig;
    mav::HomePosition h;
    h.latitude = 1'991'700'000;
    h.longitude = 19'866'000;
    rig.feed(h);
    EXPECT_FALSE(rig.driver.telemetry().home);
    EXPECT_EQ(rig.driver.status().refused_values, 1u);
}

TEST(TelemetryChecks, AStatusTextOfAnyBytesIsEscapedAndDumpsAsJson) {
    DriverRig rig;
    mav::Statustext t;
    t.severity = 2;
    const std::string raw = std::string("PreArm: \xff\xfe bad\x01\x1b[2J \xc3\xa9t\xc3") + "\\";
    mav::set_text(t.text, raw);
    rig.feed(t);
    ASSERT_EQ(rig.events.size(), 1u);
    const auto& text = std::get<StatusText>(rig.events[0]).text;
    EXPECT_EQ(text, "PreArm: \\xff\\xfe bad\\x01\\x1b[2J \xc3\xa9t\\xc3\\\\");
    const nlohmann::json doc = {{"text", text}};
    EXPECT_NO_THROW((void)doc.dump());
}

TEST(Printable, PassesUtf8AndEscapesEverythingElse) {
    EXPECT_EQ(printable("Reached waypoint #3 dist 1m"), "Reached waypoint #3 dist 1m");
    EXPECT_EQ(printable("caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x9a\x97"),
              "caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x9a\x97");
    EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");                    // overlong
    EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");           // a surrogate
    EXPECT_EQ(printable("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");  // past U+10FFFF
    EXPECT_EQ(printable(std::string("a\0b", 3)), "a\\x00b");
    EXPECT_EQ(printable("line\nbreak\x7f"), "line\\x0abreak\\x7f");
    EXPECT_EQ(printable("\\x41"), "\\\\x41") << "a backslash in the text cannot pass for an escape";
}

TEST(PositionProblem, NamesWhatIsWrong) {
    EXPECT_EQ(position_problem(412'756'000, 19'866'000), "");
    EXPECT_EQ(position_problem(900'000'000, 1'800'000'000), "");
    EXPECT_EQ(position_problem(-900'000'001, 0), "latitude -90.0000001 outside ±90");
    EXPECT_EQ(position_problem(0, 0), "latitude and longitude 0 (no fix yet)");
    EXPECT_EQ(float_problem("ATTITUDE.roll", std::nanf("")), "ATTITUDE.roll is NaN");
    EXPECT_EQ(float_problem("ATTITUDE.roll", 1.0f), "");
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot

namespace airseg::autopilot {
namespace {

namespace mav = airseg::mavlink;

TEST(MissionReceiverBound, AnUploadAnnouncingMoreThanTheMaximumIsAnsweredNoSpace) {
    MissionReceiver receiver{1, 1};
    mav::Encoder gcs{255, 190};
    mav::MissionCount c;
    c.target_system = 1;
    c.target_component = 1;
    c.count = 65535;
    bool taken = false;
    mav::Parser parser;
    parser.push(gcs.encode(c), [&](const mav::Frame& f) { taken = receiver.handle_frame(f, TimePoint{}); });
    ASSERT_TRUE(taken);
    EXPECT_TRUE(receiver.idle());
    EXPECT_EQ(receiver.refused_too_large(), 1u);
    std::optional<mav::MissionAck> ack;
    std::size_t requests = 0;
    mav::Parser answers;
    for (const auto& f : receiver.take_output()) {
        answers.push(f.bytes, [&](const mav::Frame& fr) {
            if (fr.msgid == mav::MissionAck::kId) {
                ack = mav::decode_payload<mav::MissionAck>(fr.payload_view());
            }
            requests += fr.msgid == mav::MissionRequestInt::kId ? 1 : 0;
        });
    }
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->type, mav::kMissionNoSpace);
    EXPECT_EQ(requests, 0u) << "not one item asked for";
}

TEST(MissionReceiverBound, ALongRefusalIsCutToAFewTexts) {
    MissionReceiver receiver{1, 1};
    mav::Encoder gcs{255, 190};
    mav::MissionCount c;
    c.target_system = 1;
    c.count = 2;
    mav::MissionItemInt item;
    item.target_system = 1;
    item.command = mav::kCmdNavWaypoint;
    item.frame = mav::kFrameGlobalRelativeAltInt;
    item.x = 412'756'000;
    item.y = 19'866'000;
    mav::Parser parser;
    auto send = [&](const auto& m) {
        parser.push(gcs.encode(m), [&](const mav::Frame& f) { receiver.handle_frame(f, TimePoint{}); });
    };
    send(c);
    send(item);
    item.seq = 1;
    send(item);
    ASSERT_TRUE(receiver.poll_mission());
    (void)receiver.take_output();
    std::string reason;
    for (int i = 0; i < 500; ++i) {
        reason += "word" + std::to_string(i) + " ";
    }
    receiver.answer(false, reason);
    std::size_t texts = 0;
    mav::Parser answers;
    for (const auto& f : receiver.take_output()) {
        answers.push(f.bytes,
                     [&](const mav::Frame& fr) { texts += fr.msgid == mav::Statustext::kId ? 1 : 0; });
    }
    EXPECT_EQ(texts, MissionReceiver::kMaxTextLines);
}

}  // namespace
}  // namespace airseg::autopilot
