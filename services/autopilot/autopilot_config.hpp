#pragma once
// Configuration of the autopilot driver cores. Every field has a default; validate() lists every problem,
// naming the YAML key (written next to each field) so the loader can report it as given.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/time.hpp"

namespace airseg::autopilot {

enum class Board : std::uint8_t {
    Apm2,     // APM 2.x on USB: the open resets it; MAVLink 1; REQUEST_DATA_STREAM; SET_MODE
    Pixhawk,  // Pixhawk class on a UART: no reset on open; MAVLink 2; SET_MESSAGE_INTERVAL; DO_SET_MODE
};
const char* to_string(Board b);

/// ArduPilot's REQUEST_DATA_STREAM groups (MAV_DATA_STREAM).
enum class DataStream : std::uint8_t {
    RawSensors = 1,
    ExtendedStatus = 2,
    RcChannels = 3,
    Position = 6,
    Extra1 = 10,
    Extra2 = 11,
    Extra3 = 12,
};

struct StreamRate {
    DataStream stream = DataStream::Position;
    unsigned hz = 0;
};
struct MessageRate {
    std::uint32_t msgid = 0;  // yaml: by name, e.g. GLOBAL_POSITION_INT
    double hz = 0.0;
};
struct ParamSetting {
    std::string name;  // at most 16 characters
    double value = 0.0;
};

/// The id of the MAVLink message called `name` ("ATTITUDE", any message of ArduPilot's dialect), for
/// autopilot.message_rates and the forwarding rates; nullopt when it is not in the dialect. Keeps message
/// names in the autopilot layer.
std::optional<std::uint32_t> message_id(std::string_view name);

struct RcOverrideConfig {
    double rate_hz = 10.0;                       // autopilot.rc_override.rate_hz (1..50)
    Duration input_timeout = milliseconds(500);  // autopilot.rc_override.input_timeout (0.1..5 s)
    unsigned steering_channel = 1;               // autopilot.rc_override.steering_channel (1..8)
    unsigned throttle_channel = 3;               // autopilot.rc_override.throttle_channel (1..8)
    unsigned pwm_min = 1100;                     // autopilot.rc_override.pwm_min
    unsigned pwm_trim = 1500;                    // autopilot.rc_override.pwm_trim
    unsigned pwm_max = 1900;                     // autopilot.rc_override.pwm_max
    unsigned release_repeats = 3;                // release frames sent when input goes stale (1..10)
};

struct MissionConfig {
    Duration initial_timeout = milliseconds(1500);  // autopilot.mission.initial_timeout, before RTT is known
    Duration min_timeout = milliseconds(150);       // autopilot.mission.min_timeout
    Duration max_timeout = seconds(6);              // autopilot.mission.max_timeout
    unsigned retries = 5;  // autopilot.mission.retries: per step, refreshed on progress...
    Duration give_up_after =
        seconds(15);  // autopilot.mission.give_up_after: ...and this long without progress
    Duration vehicle_gives_up =
        seconds(8);                 // autopilot.mission.vehicle_gives_up: an upload without any
                                    // request this long was abandoned by the vehicle (ArduPilot: 8 s)
    bool use_int = true;            // autopilot.mission.use_int: MISSION_REQUEST_INT / ITEM_INT
    std::uint16_t max_items = 700;  // autopilot.mission.max_items
};

/// When the driver arms the autopilot (autopilot.arming). A board that needs arming (ArduPilot Rover 4.x:
/// ARMING_REQUIRE 1) shows it by a heartbeat without MAV_MODE_FLAG_SAFETY_ARMED.
enum class ArmingPolicy : std::uint8_t {
    Auto,   // arm (never forced) on a request for WAYPOINT_NAVIGATION or MANUAL_NAVIGATION while disarmed
    Never,  // never arm: someone else does (the RC transmitter, a ground station)
};
const char* to_string(ArmingPolicy p);

/// MAV_TYPE values our own HEARTBEAT can carry.
inline constexpr std::uint8_t kMavTypeGcs = 6;
inline constexpr std::uint8_t kMavTypeOnboardController = 18;

struct AutopilotConfig {
    Board board = Board::Apm2;                // autopilot.board: apm2 | pixhawk
    std::vector<unsigned> bauds = {115200};   // autopilot.baud (one) or autopilot.bauds (tried in turn)
    Duration baud_probe = seconds(3);         // autopilot.baud_probe: time for a valid frame at one baud
    bool reset_on_open = true;                // autopilot.reset_on_open (default: board == apm2)
    Duration boot_timeout = seconds(30);      // autopilot.boot_timeout (1..120 s)
    Duration heartbeat_timeout = seconds(3);  // autopilot.heartbeat_timeout (0.5..30 s)
    std::uint8_t own_sysid = 255;             // autopilot.own_sysid
    std::uint8_t own_compid = 191;            // autopilot.own_compid (MAV_COMP_ID_ONBOARD_COMPUTER)
    std::uint8_t target_sysid = 1;            // autopilot.target_sysid
    std::uint8_t target_compid = 1;           // autopilot.target_compid
    bool gcs_heartbeat = true;                // autopilot.gcs_heartbeat (off: false): send our 1 Hz HEARTBEAT
    std::uint8_t gcs_heartbeat_type = kMavTypeGcs;  // autopilot.gcs_heartbeat: gcs | onboard
    int mavlink_version = 1;                        // autopilot.mavlink_version: 1 | 2 (default per board)
    bool use_message_interval = false;              // autopilot.use_message_interval (default per board)
    std::vector<StreamRate> stream_rates;           // autopilot.streams: {position: 4, extra1: 4, ...}
    std::vector<MessageRate> message_rates;         // autopilot.message_rates: {GLOBAL_POSITION_INT: 4, ...}
    std::vector<ParamSetting> params;               // autopilot.params: {NAME: value, ...}
    Duration param_timeout = seconds(1);            // autopilot.param_timeout: per PARAM_SET / read attempt
    unsigned param_retries = 3;                     // autopilot.param_retries
    Duration param_list_timeout = seconds(60);      // autopilot.param_list_timeout: the whole download
    Duration mode_timeout = milliseconds(1500);     // autopilot.mode_timeout: per attempt
    unsigned mode_retries = 3;                      // autopilot.mode_retries
    ArmingPolicy arming = ArmingPolicy::Auto;       // autopilot.arming: auto | never
    Duration unresponsive_timeout = seconds(20);    // autopilot.reset.unresponsive_timeout
    unsigned max_reset_pulses = 3;                  // autopilot.reset.max_pulses (0: never pulse)
    MissionConfig mission;
    RcOverrideConfig rc_override;

    /// The defaults of a board: version, stream method, reset-on-open and stream rates.
    static AutopilotConfig defaults_for(Board board);

    /// Every problem found, each naming its key; empty when valid.
    static std::vector<std::string> validate(const AutopilotConfig& config);
};

}  // namespace airseg::autopilot
