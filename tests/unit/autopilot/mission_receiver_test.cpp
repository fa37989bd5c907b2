// MissionReceiver in simulated time: a ground station's upload, its items, retries and the verdict.
#include "services/autopilot/mission_receiver.hpp"

#include <gtest/gtest.h>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::autopilot {
namespace {

namespace mav = airseg::mavlink;

const TimePoint kStart = TimePoint{} + std::chrono::hours(1);

/// QGroundControl on its default ids, uploading to the autopilot (1/1) through airsegd.
struct Station {
    MissionReceiver receiver{1, 1};
    mav::Encoder gcs{255, 190};
    std::vector<mav::Frame> answers;

    bool send(const auto& m, TimePoint now = kStart) {
        bool taken = false;
        mav::Parser p;
        p.push(gcs.encode(m), [&](const mav::Frame& f) { taken = receiver.handle_frame(f, now); });
        collect();
        return taken;
    }
    void collect() {
        mav::Parser p;
        for (const auto& f : receiver.take_output()) {
            p.push(f.bytes, [&](const mav::Frame& fr) { answers.push_back(fr); });
        }
    }
    std::vector<std::string> texts() const {
        std::vector<std::string> out;
        for (const auto& f : answers) {
            if (f.msgid == mav::Statustext::kId) {
                out.emplace_back(mav::text_of(mav::decode_payload<mav::Statustext>(f.payload_view()).text));
            }
        }
        return out;
    }
    std::optional<mav::MissionAck> last_ack() const {
        for (auto it = answers.rbegin(); it != answers.rend(); ++it) {
            if (it->msgid == mav::MissionAck::kId) {
                return mav::decode_payload<mav::MissionAck>(it->payload_view());
            }
        }
        return std::nullopt;
    }
};

mav::MissionCount count_of(std::uint16_t n) {
    mav::MissionCount c;
    c.target_system = 1;
    c.target_component = 1;
    c.count = n;
    return c;
}

mav::MissionItemInt item(std::uint16_t seq, std::uint16_t command, double lat = 41.39, double lon = 2.11,
                         float param1 = 0) {
    mav::MissionItemInt i;
    i.target_system = 1;
    i.target_component = 1;
    i.seq = seq;
    i.frame = mav::kFrameGlobalRelativeAltInt;
    i.command = command;
    i.param1 = param1;
    i.x = static_cast<std::int32_t>(lat * 1e7);
    i.y = static_cast<std::int32_t>(lon * 1e7);
    return i;
}

TEST(MissionReceiver, AnUploadIsRequestedItemByItemAndAcceptedOnTheVerdict) {
    Station s;
    EXPECT_TRUE(s.send(count_of(5)));
    ASSERT_EQ(s.answers.size(), 1u);
    const auto r0 = mav::decode_payload<mav::MissionRequestInt>(s.answers[0].payload_view());
    EXPECT_EQ(r0.seq, 0);
    EXPECT_EQ(r0.target_system, 255);
    EXPECT_EQ(r0.target_component, 190);
    EXPECT_TRUE(s.send(item(0, mav::kCmdNavWaypoint)));  // home: skipped
    EXPECT_TRUE(s.send(item(1, mav::kCmdNavWaypoint, 41.40, 2.12)));
    EXPECT_TRUE(s.send(item(2, mav::kCmdDoChangeSpeed)));  // ignored
    EXPECT_TRUE(s.send(item(3, mav::kCmdNavLoiterTime, 41.41, 2.13, 30)));
    EXPECT_FALSE(s.receiver.poll_mission());
    EXPECT_TRUE(s.send(item(4, mav::kCmdNavLoiterUnlim, 41.42, 2.14)));
    EXPECT_EQ(s.answers.size(), 5u);  // a request for each item, nothing else yet
    const auto m = s.receiver.poll_mission();
    ASSERT_TRUE(m);
    EXPECT_EQ(m->sysid, 255);
    EXPECT_EQ(m->compid, 190);
    ASSERT_EQ(m->items.size(), 3u);
    EXPECT_NEAR(m->items[0].lat, 41.40, 1e-7);
    EXPECT_NEAR(m->items[0].lon, 2.12, 1e-7);
    EXPECT_EQ(m->items[1].hold_s, 30.0);
    EXPECT_EQ(m->items[2].kind, MissionItem::Kind::Stop);
    EXPECT_FALSE(s.receiver.idle());
    EXPECT_EQ(s.receiver.poll_timeout(), kNever);  // the verdict takes as long as loading the plan takes
    s.receiver.answer(true, "");
    s.collect();
    ASSERT_TRUE(s.last_ack());
    EXPECT_EQ(s.last_ack()->type, mav::kMissionAccepted);
    EXPECT_EQ(s.last_ack()->target_component, 190);
    EXPECT_TRUE(s.receiver.idle());
}

TEST(MissionReceiver, ARefusalIsADeniedAckWithTheReasonInShortTexts) {
    Station s;
    s.send(count_of(2));
    s.send(item(0, mav::kCmdNavWaypoint));
    s.send(item(1, mav::kCmdNavWaypoint));
    ASSERT_TRUE(s.receiver.poll_mission());
    s.receiver.answer(false,
                      "airseg: a flight plan is running (survey); pause is not enough: stop it or load the "
                      "mission as a plan with airsegctl plan load");
    s.collect();
    EXPECT_EQ(s.last_ack()->type, mav::kMissionDenied);
    const auto texts = s.texts();
    ASSERT_GE(texts.size(), 3u);
    for (const auto& t : texts) {
        EXPECT_LE(t.size(), 50u);
    }
    EXPECT_EQ(texts[0], "airseg: a flight plan is running (survey); pause");
}

TEST(MissionReceiver, AnItemWithoutAPlanEquivalentEndsTheUploadNamingIt) {
    Station s;
    s.send(count_of(6));
    for (std::uint16_t i = 0; i < 4; ++i) {
        s.send(item(i, mav::kCmdNavWaypoint));
    }
    s.send(item(4, mav::kCmdDoSetServo));
    ASSERT_TRUE(s.last_ack());
    EXPECT_EQ(s.last_ack()->type, mav::kMissionUnsupported);
    std::string all;
    for (const auto& t : s.texts()) {
        all += t + " ";
    }
    EXPECT_NE(all.find("item 4: MAV_CMD_DO_SET_SERVO (183) has no flight plan equivalent"), std::string::npos)
        << all;
    EXPECT_TRUE(s.receiver.idle());
    EXPECT_FALSE(s.receiver.poll_mission());
}

TEST(MissionReceiver, AFloatItemIsAnsweredWithFloatRequests) {
    Station s;
    s.send(count_of(3));
    mav::MissionItem f;
    f.target_system = 1;
    f.seq = 0;
    f.frame = mav::kFrameGlobalRelativeAlt;
    f.command = mav::kCmdNavWaypoint;
    s.send(f);
    EXPECT_EQ(s.answers.back().msgid, mav::MissionRequest::kId);
    f.seq = 1;
    f.x = 41.5f;
    f.y = 2.25f;
    s.send(f);
    f.seq = 2;
    s.send(f);
    const auto m = s.receiver.poll_mission();
    ASSERT_TRUE(m);
    ASSERT_EQ(m->items.size(), 2u);
    EXPECT_NEAR(m->items[0].lat, 41.5, 1e-5);
}

TEST(MissionReceiver, AnUnansweredRequestIsRepeatedThenTheUploadIsCancelled) {
    Station s;
    s.send(count_of(3));
    TimePoint sent = kStart;
    for (unsigned i = 0; i < 5; ++i) {
        const auto now = s.receiver.poll_timeout();
        EXPECT_EQ(now - sent, milliseconds(1500));
        sent = now;
        s.receiver.handle_timeout(now);
        s.collect();
    }
    EXPECT_EQ(s.answers.size(), 6u);  // the first request and five repeats
    s.receiver.handle_timeout(s.receiver.poll_timeout());
    s.collect();
    ASSERT_TRUE(s.last_ack());
    EXPECT_EQ(s.last_ack()->type, mav::kMissionOperationCancelled);
    EXPECT_TRUE(s.receiver.idle());
    EXPECT_EQ(s.receiver.poll_timeout(), kNever);
}

TEST(MissionReceiver, AnotherStationIsDeniedWhileAnUploadRunsAndOtherFramesAreNotTaken) {
    Station s;
    s.send(count_of(3));
    mav::Encoder other{254, 190};
    bool taken = false;
    mav::Parser p;
    p.push(other.encode(count_of(2)),
           [&](const mav::Frame& f) { taken = s.receiver.handle_frame(f, kStart); });
    s.collect();
    EXPECT_TRUE(taken);
    EXPECT_EQ(s.last_ack()->type, mav::kMissionDenied);
    EXPECT_EQ(s.last_ack()->target_system, 254);
    auto fence = count_of(4);
    fence.mission_type = 1;
    EXPECT_FALSE(s.send(fence));
    auto elsewhere = count_of(4);
    elsewhere.target_system = 7;
    EXPECT_FALSE(s.send(elsewhere));
    EXPECT_FALSE(s.send(mav::MissionRequestList{}));
}

TEST(MissionReceiver, StatustextLinesFitTheField) {
    EXPECT_TRUE(statustext_lines("").empty());
    EXPECT_EQ(statustext_lines("short"), std::vector<std::string>{"short"});
    const auto long_word = statustext_lines(std::string(120, 'x'));
    ASSERT_EQ(long_word.size(), 3u);
    EXPECT_EQ(long_word[2].size(), 20u);
}

}  // namespace
}  // namespace airseg::autopilot
