// The derived layouts against the values published with the MAVLink C headers generated from the same
// definitions (MAVLINK_MESSAGE_CRCS: id, CRC_EXTRA, minimum length, maximum length, target flags,
// target_system offset, target_component offset).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string_view>

#include "services/autopilot/mavlink/crc.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::mavlink {
namespace {

struct Published {
    std::uint32_t id;
    std::uint8_t crc_extra;
    std::uint8_t min_length;
    std::uint8_t max_length;
    std::uint8_t target_flags;  // 1: has target_system, 2: has target_component
    std::uint8_t target_system_offset;
    std::uint8_t target_component_offset;
};

// clang-format off
constexpr std::array<Published, 42> kPublished{{
    {0, 50, 9, 9, 0, 0, 0},       {1, 124, 31, 43, 0, 0, 0},    {2, 137, 12, 12, 0, 0, 0},
    {11, 89, 6, 6, 1, 4, 0},      {20, 214, 20, 20, 3, 2, 3},   {21, 159, 2, 2, 3, 0, 1},
    {22, 220, 25, 25, 0, 0, 0},   {23, 168, 23, 23, 3, 4, 5},   {24, 24, 30, 52, 0, 0, 0},
    {30, 39, 28, 28, 0, 0, 0},    {33, 104, 28, 28, 0, 0, 0},   {35, 244, 22, 22, 0, 0, 0},
    {36, 222, 21, 37, 0, 0, 0},   {38, 9, 6, 7, 3, 4, 5},       {39, 254, 37, 38, 3, 32, 33},
    {40, 230, 4, 5, 3, 2, 3},     {41, 28, 4, 4, 3, 2, 3},      {42, 28, 2, 18, 0, 0, 0},
    {43, 132, 2, 3, 3, 0, 1},     {44, 221, 4, 9, 3, 2, 3},     {45, 232, 2, 3, 3, 0, 1},
    {46, 11, 2, 2, 0, 0, 0},      {47, 153, 3, 8, 3, 0, 1},     {51, 196, 4, 5, 3, 2, 3},
    {62, 183, 26, 26, 0, 0, 0},   {65, 118, 42, 42, 0, 0, 0},   {66, 148, 6, 6, 3, 2, 3},
    {70, 124, 18, 38, 3, 16, 17}, {73, 38, 37, 38, 3, 32, 33},  {74, 20, 20, 20, 0, 0, 0},
    {76, 152, 33, 33, 3, 30, 31}, {77, 143, 3, 10, 3, 8, 9},    {109, 185, 9, 9, 0, 0, 0},
    {147, 154, 36, 54, 0, 0, 0},  {148, 178, 60, 78, 0, 0, 0},  {242, 104, 52, 60, 0, 0, 0},
    {253, 83, 51, 54, 0, 0, 0},
    // COMMAND_INT, SET_POSITION_TARGET_GLOBAL_INT, POSITION_TARGET_GLOBAL_INT, FILE_TRANSFER_PROTOCOL, TIMESYNC
    {75, 158, 35, 35, 3, 30, 31}, {86, 5, 53, 53, 3, 50, 51},   {87, 150, 51, 51, 0, 0, 0},
    {110, 84, 254, 254, 3, 1, 2}, {111, 34, 16, 18, 3, 16, 17},
}};
// clang-format on

TEST(MavlinkCrc, X25CheckValue) {
    // The catalogue check value of CRC-16/MCRF4XX.
    Crc16 crc;
    crc.add(std::string_view("123456789"));
    EXPECT_EQ(crc.value(), 0x6F91);
}

TEST(MavlinkCrcExtra, EveryDeclaredMessageHasAPublishedEntry) {
    EXPECT_EQ(all_messages().size(), kPublished.size());
    for (const MessageInfo& m : all_messages()) {
        bool found = false;
        for (const Published& p : kPublished) {
            found = found || p.id == m.id;
        }
        EXPECT_TRUE(found) << m.name;
    }
}

TEST(MavlinkCrcExtra, DerivedValuesMatchPublishedOnes) {
    for (const Published& p : kPublished) {
        const MessageInfo* m = find_message(p.id);
        ASSERT_NE(m, nullptr) << "message id " << p.id << " is not declared";
        EXPECT_EQ(m->crc_extra, p.crc_extra) << m->name;
        EXPECT_EQ(m->base_length, p.min_length) << m->name;
        EXPECT_EQ(m->length, p.max_length) << m->name;
        if (p.target_flags & 1) {
            const FieldInfo* f = m->find_field("target_system");
            ASSERT_NE(f, nullptr) << m->name;
            EXPECT_EQ(f->offset, p.target_system_offset) << m->name;
        }
        if (p.target_flags & 2) {
            const FieldInfo* f = m->find_field("target_component");
            ASSERT_NE(f, nullptr) << m->name;
            EXPECT_EQ(f->offset, p.target_component_offset) << m->name;
        }
    }
}

TEST(MavlinkCrcExtra, IsAvailableAtCompileTime) {
    static_assert(MessageTraits<Heartbeat>::layout.crc_extra == 50);
    static_assert(MessageTraits<Statustext>::layout.crc_extra == 83);
    static_assert(MessageTraits<MissionItemInt>::layout.crc_extra == 38);
    SUCCEED();
}

TEST(MavlinkLayout, BaseFieldsSortBySizeStablyAndExtensionsFollowInOrder) {
    // GPS_RAW_INT: fix_type is declared second but, as a uint8_t, goes after all wider base fields;
    // the extensions keep their declaration order even though yaw (uint16_t) is narrower.
    const MessageInfo* m = find_message("GPS_RAW_INT");
    ASSERT_NE(m, nullptr);
    std::array<std::string_view, 16> expected{"time_usec",     "lat",
                                              "lon",           "alt",
                                              "eph",           "epv",
                                              "vel",           "cog",
                                              "fix_type",      "satellites_visible",
                                              "alt_ellipsoid", "h_acc",
                                              "v_acc",         "vel_acc",
                                              "hdg_acc",       "yaw"};
    ASSERT_EQ(m->fields.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(m->fields[i].name, expected[i]) << i;
        EXPECT_EQ(m->fields[i].extension, i >= 10) << i;
    }
    EXPECT_EQ(m->find_field("yaw")->offset, 50);
}

TEST(MavlinkLayout, ArraysSortByElementSize) {
    // BATTERY_STATUS: voltages (uint16_t[10]) sorts with the 2-byte fields, not as a 20-byte block.
    const MessageInfo* m = find_message("BATTERY_STATUS");
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->find_field("current_consumed")->offset, 0);
    EXPECT_EQ(m->find_field("energy_consumed")->offset, 4);
    EXPECT_EQ(m->find_field("temperature")->offset, 8);
    EXPECT_EQ(m->find_field("voltages")->offset, 10);
    EXPECT_EQ(m->find_field("voltages")->array_length, 10);
    EXPECT_EQ(m->find_field("current_battery")->offset, 30);
    EXPECT_EQ(m->find_field("voltages_ext")->offset, 41);
}

TEST(MavlinkMessageTable, LooksUpByIdAndName) {
    EXPECT_EQ(find_message(0)->name, "HEARTBEAT");
    EXPECT_EQ(find_message("COMMAND_LONG")->id, 76u);
    EXPECT_EQ(find_message(9999), nullptr);
    EXPECT_EQ(find_message("NO_SUCH_MESSAGE"), nullptr);
    EXPECT_EQ(find_message(0)->find_field("no_such_field"), nullptr);
}

}  // namespace
}  // namespace airseg::mavlink
