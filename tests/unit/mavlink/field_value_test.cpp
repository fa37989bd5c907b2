#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "services/autopilot/mavlink/field_value.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::mavlink {
namespace {

TEST(MavlinkFieldValue, GenericReadsMatchTypedEncoding) {
    SysStatus s;
    s.current_battery = -250;
    s.battery_remaining = -1;
    s.onboard_control_sensors_health = 0xFFFFFFFF;
    std::array<std::uint8_t, kMaxPayload> payload{};
    encode_payload(s, payload);
    const MessageInfo* m = find_message("SYS_STATUS");
    EXPECT_EQ(std::get<std::int64_t>(read_element(*m->find_field("current_battery"), payload, 0)), -250);
    EXPECT_EQ(std::get<std::int64_t>(read_element(*m->find_field("battery_remaining"), payload, 0)), -1);
    EXPECT_EQ(
        std::get<std::uint64_t>(read_element(*m->find_field("onboard_control_sensors_health"), payload, 0)),
        0xFFFFFFFFu);
}

TEST(MavlinkFieldValue, GenericWritesDecodeThroughTypedStructs) {
    const MessageInfo* m = find_message("HOME_POSITION");
    std::array<std::uint8_t, kMaxPayload> payload{};
    EXPECT_EQ(write_element(*m->find_field("latitude"), payload, 0, std::int64_t{-473977418}),
              WriteResult::Ok);
    EXPECT_EQ(write_element(*m->find_field("q"), payload, 3, 0.25), WriteResult::Ok);
    EXPECT_EQ(write_element(*m->find_field("time_usec"), payload, 0, std::uint64_t{0xFFFFFFFFFFFFFFFFull}),
              WriteResult::Ok);
    const HomePosition h = decode_payload<HomePosition>(payload);
    EXPECT_EQ(h.latitude, -473977418);
    EXPECT_EQ(h.q[3], 0.25f);
    EXPECT_EQ(h.time_usec, 0xFFFFFFFFFFFFFFFFull);
}

TEST(MavlinkFieldValue, WritesRefuseValuesThatDoNotFit) {
    const MessageInfo* m = find_message("HEARTBEAT");
    std::array<std::uint8_t, kMaxPayload> payload{};
    EXPECT_EQ(write_element(*m->find_field("type"), payload, 0, std::int64_t{256}), WriteResult::OutOfRange);
    EXPECT_EQ(write_element(*m->find_field("type"), payload, 0, std::int64_t{-1}), WriteResult::OutOfRange);
    EXPECT_EQ(write_element(*m->find_field("type"), payload, 0, 1.5), WriteResult::WrongKind);
    EXPECT_EQ(write_element(*m->find_field("custom_mode"), payload, 0, std::uint64_t{0xFFFFFFFF}),
              WriteResult::Ok);
    EXPECT_EQ(write_element(*m->find_field("custom_mode"), payload, 0, std::uint64_t{0x100000000}),
              WriteResult::OutOfRange);
}

}  // namespace
}  // namespace airseg::mavlink
