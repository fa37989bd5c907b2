#pragma once
// Frames produced by an independent MAVLink implementation (node-mavlink 2.3.0 with the mavlink-mappings
// definitions), used as golden vectors for both directions of the codec.
#include <cstdint>
#include <string_view>
#include <vector>

namespace airseg::mavlink::test {

inline std::vector<std::uint8_t> from_hex(std::string_view hex) {
    std::vector<std::uint8_t> out;
    auto nibble = [](char c) { return static_cast<std::uint8_t>(c <= '9' ? c - '0' : c - 'a' + 10); };
    for (std::size_t i = 0; i + 1 < hex.size(); i += 2) {
        out.push_back(static_cast<std::uint8_t>(nibble(hex[i]) << 4 | nibble(hex[i + 1])));
    }
    return out;
}

// HEARTBEAT type=10 autopilot=3 base_mode=0x59 custom_mode=4 system_status=4 mavlink_version=3, seq 7, 1/1.
inline constexpr std::string_view kHeartbeatV1 = "fe0907010100040000000a03590403e6d9";
inline constexpr std::string_view kHeartbeatV2 = "fd090000070101000000040000000a03590403b8d8";
// GPS_RAW_INT time_usec=123456789012 fix_type=3 lat=473977418 lon=85455939 alt=488000 eph=121 epv=65535
// vel=15 cog=27000 satellites_visible=10, extensions zero (truncated away), seq 200, 1/1.
inline constexpr std::string_view kGpsRawIntV2 =
    "fd1e0000c80101180000141a99be1c0000004a52401c43f41705407207007900ffff0f007869030a31ad";
// STATUSTEXT severity=6 text="Mission: 1 WP", seq 0, 1/1 (payload truncated after the text).
inline constexpr std::string_view kStatustextV2 = "fd0e0000000101fd0000064d697373696f6e3a2031205750f706";
// COMMAND_LONG target 1/1 command=400 confirmation=0 param1=1 param2=21196 param7=-0.5, seq 9, from 255/190.
inline constexpr std::string_view kCommandLongV2 =
    "fd20000009ffbe4c00000000803f0098a54600000000000000000000000000000000000000bf90010101ec40";
// PARAM_VALUE param_id="SYSID_THISMAV" param_value=1.5 param_type=9 param_count=900 param_index=17, seq 3.
inline constexpr std::string_view kParamValueV1 =
    "fe19030101160000c03f8403110053595349445f544849534d4156000000098112";

}  // namespace airseg::mavlink::test
