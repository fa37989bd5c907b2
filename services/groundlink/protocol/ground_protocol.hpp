#pragma once
// The ground protocol: what airsegd and airsegctl say to each other inside ground-link transport messages.
// Compact binary, explicit little-endian, versioned; an unknown message type is skipped, not an error.
// Layouts are in docs/ground-protocol.md.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

namespace airseg::groundlink::protocol {

inline constexpr std::uint8_t kVersion = 1;

/// Transport priorities (Safe channels) and Fast topics used by the protocol.
inline constexpr std::uint8_t kPriorityControl = 0;    // commands and their results
inline constexpr std::uint8_t kPriorityTelemetry = 1;  // vehicle state
inline constexpr std::uint8_t kPriorityStatus = 2;     // link statistics, events
inline constexpr std::uint8_t kPriorityBulk = 3;       // flight plans, parameter lists
inline constexpr std::uint16_t kTopicTelemetry = 1;
inline constexpr std::uint16_t kTopicLinkStats = 2;
inline constexpr std::uint16_t kTopicJoystick = 3;
inline constexpr std::uint16_t kTopicReception = 4;
/// Fast topics of forwarded MAVLink frames: one per message id, so only the freshest frame of an id waits.
/// Ids above 0x7fff share topics modulo 0x8000 (none of the common telemetry messages is that high).
inline constexpr std::uint16_t kTopicMavlinkBase = 0x8000;
inline constexpr std::uint16_t mavlink_topic(std::uint32_t msgid) {
    return static_cast<std::uint16_t>(kTopicMavlinkBase | (msgid & 0x7fff));
}

enum class MessageType : std::uint8_t {
    Telemetry = 0x01,
    LinkStats = 0x02,
    Event = 0x04,
    Command = 0x10,
    Result = 0x11,
    Joystick = 0x12,
    Reception = 0x13,
    CommandDeflated = 0x14,  ///< a command whose CBOR is compressed (deflate_codec.hpp)
    ResultDeflated = 0x15,   ///< a result whose CBOR is compressed
    MavlinkFrames = 0x16,    ///< whole MAVLink frames for or from a standard ground station
};

/// One vehicle telemetry sample. Units are chosen so the whole message fits 29 bytes.
struct Telemetry {
    double lat_deg = 0;  // 1e-7 degree resolution
    double lon_deg = 0;
    double alt_m = 0;             // 0.1 m resolution, ±3276 m
    double ground_speed_mps = 0;  // 0.01 m/s, up to 655 m/s
    double heading_deg = 0;       // 0.01 degree, 0..360
    int roll_deg = 0;             // whole degrees, ±127
    int pitch_deg = 0;
    double battery_v = 0;            // 1 mV
    std::optional<int> battery_pct;  // 0..100; absent when unknown
    std::uint8_t gps_fix = 0;        // 0..15 (MAV_GPS_FIX_TYPE values)
    std::uint8_t satellites = 0;     // capped at 15
    std::uint8_t vehicle_state = 0;  // autopilot-neutral vehicle state (0..15)
    std::uint8_t mode = 0;           // autopilot mode number (0..255)
    std::uint8_t plan_state = 0;     // 0 none, 1 running, 2 paused, 3 done, 4 interrupted, 5 failed
    // Latitude and longitude hold no place (none reported yet, no fix, or a value the vehicle refused); they
    // are then 0. Byte 22, bit 7; a vehicle that predates it always sends 0 there.
    bool no_position = false;
    std::uint16_t plan_element = 0;   // capped at 16383
    std::uint32_t next_waypoint = 0;  // index in the expanded plan, capped at 2^24-1

    bool operator==(const Telemetry&) const = default;
};

struct LinkStatsReport {
    std::uint16_t rtt_ms = 0;
    std::uint16_t loss_permille = 0;
    std::uint32_t goodput_bps = 0;  // delivered message bytes per second, both classes
    std::uint32_t retransmissions = 0;
    std::uint32_t mac_failures = 0;
    bool operator==(const LinkStatsReport&) const = default;
};

struct Event {
    enum class Severity : std::uint8_t { Info = 0, Warning = 1, Error = 2 };
    Severity severity = Severity::Info;
    std::string text;  // at most kMaxEventText bytes
    bool operator==(const Event&) const = default;
};
inline constexpr std::size_t kMaxEventText = 200;

/// A command request: the same JSON object the local socket takes ({"cmd": ...}), carried as CBOR.
struct Command {
    std::uint32_t request_id = 0;
    nlohmann::json request;
    bool operator==(const Command&) const = default;
};

/// The answer to one Command: the dispatcher's {"ok":..} object, carried as CBOR.
struct Result {
    std::uint32_t request_id = 0;
    nlohmann::json answer;
    bool operator==(const Result&) const = default;
};

/// Operator stick input from the ground, sent as a Fast message at a fixed rate while the operator drives.
/// Each axis -1..1, carried in 1/10000 steps.
struct Joystick {
    double steering = 0;
    double throttle = 0;
    bool operator==(const Joystick&) const = default;
};

/// The ground end's count of pushed telemetry messages (telemetry samples and link statistics) received since
/// its transport session began, sent at least once a second: the vehicle compares it with what it pushed to
/// measure what the link really delivers.
struct ReceptionReport {
    std::uint32_t received = 0;
    bool operator==(const ReceptionReport&) const = default;
};

/// One or more whole MAVLink frames (v1 or v2), concatenated, carried opaquely: the ground link does not know
/// MAVLink; the autopilot room parses and checks them. Never empty.
struct MavlinkFrames {
    std::vector<std::uint8_t> bytes;
    bool operator==(const MavlinkFrames&) const = default;
};

struct Unknown {
    std::uint8_t type = 0;
    bool operator==(const Unknown&) const = default;
};

using Message = std::variant<Telemetry, LinkStatsReport, Event, Command, Result, Joystick, ReceptionReport,
                             MavlinkFrames, Unknown>;

std::vector<std::uint8_t> encode(const Message& message);

struct DecodeResult {
    std::optional<Message> message;
    std::string error;  // set when the bytes are not a valid message of a known type and version
};

DecodeResult decode(std::span<const std::uint8_t> bytes);

/// Wire codes of the telemetry's vehicle_state nibble (the autopilot-neutral states, in the order of
/// autopilot::VehicleState) and their names.
const char* vehicle_state_name(std::uint8_t code);

/// The telemetry's mode byte is the autopilot's own mode number (autopilot::Telemetry::custom_mode), carried
/// without interpretation; kModeUnknown when there is none or it does not fit below it. The names belong to
/// the autopilot's table (services/autopilot/ardupilot/rover_modes.hpp), not to the protocol.
inline constexpr std::uint8_t kModeUnknown = 255;

}  // namespace airseg::groundlink::protocol
