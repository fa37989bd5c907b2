#include "ground/param_cache.hpp"

#include <gtest/gtest.h>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::ground {
namespace {

namespace mav = airseg::mavlink;

/// Frames as a receiver's parser delivers them, with their bytes.
struct Parsed {
    mav::Frame frame;
    std::vector<std::uint8_t> bytes;
};
template <class M>
Parsed parsed(mav::Encoder& encoder, const M& m) {
    Parsed out;
    out.bytes = encoder.encode(m);
    mav::Parser parser;
    parser.push(out.bytes, [&](const mav::Frame& f) { out.frame = f; });
    return out;
}

/// The PARAM_VALUEs among `bytes`, by index.
std::map<int, mav::ParamValue> values_in(const std::vector<std::uint8_t>& bytes) {
    std::map<int, mav::ParamValue> out;
    mav::Parser parser;
    parser.push(bytes, [&](const mav::Frame& f) {
        if (auto v = mav::decode<mav::ParamValue>(f)) {
            out[v->param_index] = *v;
        }
    });
    return out;
}

class ParamCacheTest : public ::testing::Test {
  protected:
    void feed_value(std::uint16_t index, std::uint16_t count, float value, const std::string& id = {}) {
        mav::ParamValue v;
        mav::set_text(v.param_id, id.empty() ? "P" + std::to_string(index) : id);
        v.param_value = value;
        v.param_type = 9;
        v.param_count = count;
        v.param_index = index;
        const auto p = parsed(autopilot, v);
        cache.from_vehicle(p.frame, p.bytes);
    }
    void feed_all(std::uint16_t count) {
        for (std::uint16_t i = 0; i < count; ++i) {
            feed_value(i, count, static_cast<float>(i));
        }
    }
    void boot_time(std::uint32_t ms) {
        mav::Attitude a;
        a.time_boot_ms = ms;
        const auto p = parsed(autopilot, a);
        cache.from_vehicle(p.frame, p.bytes);
    }
    void system_time(std::uint32_t ms) {
        mav::SystemTime t;
        t.time_boot_ms = ms;
        const auto p = parsed(autopilot, t);
        cache.from_vehicle(p.frame, p.bytes);
    }
    bool request_list(std::vector<std::uint8_t>& out, std::uint8_t component = 0) {
        mav::ParamRequestList r;
        r.target_system = 1;
        r.target_component = component;
        return cache.answer(parsed(station, r).frame, out);
    }
    bool request_read(std::vector<std::uint8_t>& out, std::int16_t index, const std::string& id = {}) {
        mav::ParamRequestRead r;
        r.target_system = 1;
        r.target_component = 1;
        r.param_index = index;
        mav::set_text(r.param_id, id);
        return cache.answer(parsed(station, r).frame, out);
    }

    mav::Encoder autopilot{1, 1};
    mav::Encoder station{255, 190};
    ParamCache cache;
};

TEST_F(ParamCacheTest, ACompleteCacheAnswersTheWholeListInOrder) {
    std::vector<std::uint8_t> out;
    EXPECT_FALSE(request_list(out));  // empty: over the radio
    feed_all(280);
    ASSERT_TRUE(cache.fresh());
    ASSERT_TRUE(request_list(out));
    const auto values = values_in(out);
    ASSERT_EQ(values.size(), 280u);
    EXPECT_EQ(values.at(279).param_value, 279.0f);
    EXPECT_EQ(cache.stats().answered_lists, 1u);
    EXPECT_EQ(cache.stats().passed_on, 1u);
}

TEST_F(ParamCacheTest, AnIncompleteCachePassesRequestsOn) {
    for (std::uint16_t i = 0; i < 280; i += 2) {
        feed_value(i, 280, 1.0f);
    }
    std::vector<std::uint8_t> out;
    EXPECT_FALSE(cache.fresh());
    EXPECT_FALSE(request_list(out));
    EXPECT_FALSE(request_read(out, 2));
    EXPECT_TRUE(out.empty());
}

TEST_F(ParamCacheTest, ReadsByIndexAndByName) {
    feed_all(10);
    std::vector<std::uint8_t> out;
    ASSERT_TRUE(request_read(out, 4));
    EXPECT_EQ(values_in(out).at(4).param_value, 4.0f);
    out.clear();
    ASSERT_TRUE(request_read(out, -1, "P7"));
    EXPECT_EQ(values_in(out).at(7).param_value, 7.0f);
    out.clear();
    EXPECT_FALSE(request_read(out, -1, "NO_SUCH"));  // the autopilot's to answer
    EXPECT_FALSE(request_read(out, 10));
}

TEST_F(ParamCacheTest, ASetIsOutstandingUntilItsEchoUpdatesTheCache) {
    feed_all(10);
    mav::ParamSet set;
    set.target_system = 1;
    set.target_component = 1;
    mav::set_text(set.param_id, "P3");
    set.param_value = 33.0f;
    std::vector<std::uint8_t> out;
    EXPECT_FALSE(cache.answer(parsed(station, set).frame, out));  // a set always goes to the autopilot
    EXPECT_FALSE(cache.fresh());
    EXPECT_FALSE(request_read(out, 3));
    feed_value(65535, 10, 33.0f, "P3");  // ArduPilot's echo of a set may carry no index
    ASSERT_TRUE(cache.fresh());
    ASSERT_TRUE(request_read(out, 3));
    EXPECT_EQ(values_in(out).at(3).param_value, 33.0f);
}

TEST_F(ParamCacheTest, AnAutopilotRebootOrAnotherCountEmptiesIt) {
    feed_all(10);
    boot_time(60'000);
    boot_time(61'000);
    EXPECT_TRUE(cache.fresh());
    boot_time(500);  // time since boot went back: rebooted
    EXPECT_FALSE(cache.fresh());
    EXPECT_EQ(cache.stats().reboots, 1u);
    EXPECT_EQ(cache.stats().entries, 0u);
    feed_all(10);
    EXPECT_TRUE(cache.fresh());
    feed_value(0, 11, 1.0f);  // a new table
    EXPECT_FALSE(cache.fresh());
    EXPECT_EQ(cache.stats().entries, 1u);
}

// The link carries each message's freshest value, in the place in its queue where an older one waited: after
// an outage one message's time may come seconds behind another's. Only a message's own time going back is a
// reboot.
TEST_F(ParamCacheTest, AMessageOlderThanAnotherMessagesIsNoRebootButItsOwnTimeGoingBackIs) {
    feed_all(10);
    boot_time(60'000);
    system_time(60'100);
    system_time(69'000);  // after an 8 s outage, SYSTEM_TIME's fresh value first,
    boot_time(61'000);    // then the ATTITUDE that waited: 8 s behind SYSTEM_TIME, ahead of its own last
    EXPECT_TRUE(cache.fresh());
    EXPECT_EQ(cache.stats().reboots, 0u);
    std::vector<std::uint8_t> out;
    EXPECT_TRUE(request_list(out));

    system_time(400);  // a reboot: SYSTEM_TIME's own time went back
    EXPECT_FALSE(cache.fresh());
    EXPECT_EQ(cache.stats().reboots, 1u);
    feed_all(10);
    boot_time(450);  // ATTITUDE's first time after it: the same reboot, the values after it kept
    EXPECT_TRUE(cache.fresh());
    EXPECT_EQ(cache.stats().reboots, 1u);
}

// The vehicle's event says so whatever frames are forwarded; the same reboot told by both signals empties
// the cache once, and a reboot after new values empties it again.
TEST_F(ParamCacheTest, TheVehiclesRebootEventEmptiesItOncePerReboot) {
    feed_all(10);
    ASSERT_TRUE(cache.fresh());
    cache.autopilot_rebooted();
    EXPECT_FALSE(cache.fresh());
    EXPECT_EQ(cache.stats().reboots, 1u);
    EXPECT_EQ(cache.stats().entries, 0u);

    feed_value(0, 10, 1.0f);
    boot_time(60'000);
    boot_time(500);  // told by the time since boot first
    EXPECT_EQ(cache.stats().reboots, 2u);
    cache.autopilot_rebooted();  // then by the event: the same reboot
    EXPECT_EQ(cache.stats().reboots, 2u);
    feed_all(10);
    EXPECT_TRUE(cache.fresh()) << "what came after the reboot is kept";
    cache.autopilot_rebooted();
    EXPECT_EQ(cache.stats().reboots, 3u);
    EXPECT_FALSE(cache.fresh());
}

TEST_F(ParamCacheTest, ItIsBoundedAndAnswersOnlyForItsAutopilot) {
    feed_value(0, 60000, 1.0f);
    feed_value(5000, 60000, 1.0f);
    EXPECT_EQ(cache.stats().overflow, 1u);
    EXPECT_FALSE(cache.fresh());
    cache.reset();
    feed_all(3);
    std::vector<std::uint8_t> out;
    EXPECT_FALSE(request_list(out, 2));  // another component of system 1
    EXPECT_TRUE(request_list(out, 1));
    mav::Encoder other{2, 1};
    mav::ParamValue v;
    v.param_count = 3;
    const auto p = parsed(other, v);
    cache.from_vehicle(p.frame, p.bytes);
    EXPECT_EQ(cache.stats().other_source, 1u);
    EXPECT_TRUE(cache.fresh());
}

}  // namespace
}  // namespace airseg::ground
