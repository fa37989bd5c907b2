#pragma once
// What the simulated board's firmware does where firmware versions differ: the wire (MAVLink 1 only or both
// versions), the mission protocol and how AUTO runs a mission, the commands served and the look of the
// telemetry. Each field names one family of behaviour so a test can build a board in-process and flip one;
// FirmwareProfile::of() gives the two boards the simulator knows:
//
//  - modern: ArduPilot Rover as it is today (the simulator's behaviour before profiles existed; the default).
//  - rover2: APMrover2 2.42..2.45 on an APM 2.5, the last releases before Rover moved to the AP_Mission
//    library (2.46, August 2014). Every behaviour is taken from that firmware's source (GCS_Mavlink.pde,
//    commands_process.pde, commands_logic.pde, commands.pde, system.pde, APMrover2.pde of ArduRover
//    v2.43; libraries/GCS_MAVLink of the same tree); docs/simulators.md lists what comes from where and what
//    could not be verified.
#include <cstdint>
#include <optional>
#include <string_view>

namespace airseg::apmsim {

enum class Firmware : std::uint8_t { Modern, Rover2 };

/// "modern", "rover2".
std::string_view firmware_name(Firmware f);
/// A firmware from its name (any case); nothing if unknown.
std::optional<Firmware> parse_firmware(std::string_view text);

/// A family of behaviour: today's ArduPilot, or APMrover2 2.4x.
enum class Dialect : std::uint8_t { Modern, Rover2 };

struct FirmwareProfile {
    Firmware firmware = Firmware::Modern;
    /// false: the board's receiver is the MAVLink 1.0 C library parser (legacy_parser.hpp); a MAVLink 2
    /// frame is line noise to it (its start bytes are counted).
    bool reads_mavlink2 = true;
    /// MISSION_REQUEST_INT (51) and MISSION_ITEM_INT (73) understood. false: ignored (the 2.x receiver has no
    /// CRC_EXTRA for them, so they fail their checksum; counted as bad_crc or ignored frames).
    bool mission_int = true;
    /// target_system 0 addresses the board. The 2.x firmware's mavlink_check_target() wants its own
    /// system id exactly (GCS_MAVLink.cpp), so a broadcast request is ignored there.
    bool broadcast_target = true;
    /// Mission protocol and mission execution: Rover2 is legacy_mission_server.hpp and the 2.x command
    /// processor (rover_sim_rover2.cpp): AUTO restarts at item 1, do-commands run between nav commands,
    /// DO_JUMP decrements its count in the stored mission, the mission ends in HOLD.
    Dialect mission = Dialect::Modern;
    /// COMMAND_LONG, SET_MODE and the guided "go to": Rover2 serves RTL, MISSION_START, DO_SET_MODE by
    /// MAV_MODE, DO_SET_SERVO, PREFLIGHT_CALIBRATION and REBOOT (no acknowledgement: the board resets),
    /// answers every other command UNSUPPORTED after a "command received: " text, and acknowledges no
    /// SET_MODE.
    Dialect commands = Dialect::Modern;
    /// Heartbeat flags, stream contents, MISSION_CURRENT (the 2.x command index, sent only in the stream and
    /// on MISSION_SET_CURRENT), parameter echo (index 65535), text severities (2.x's own 1..4).
    Dialect telemetry = Dialect::Modern;
    /// COMMAND_LONG MAV_CMD_DO_CHANGE_SPEED served (2.x answers it UNSUPPORTED).
    bool change_speed_command = true;
    /// ArduPilot 4.x arming (AP_Arming, AP_Arming_Rover): ARMING_REQUIRE defaults to 1, so the board boots
    /// disarmed and does not move until armed; arming runs the checks (ARMING_CHECK) and a failure is said
    /// as "Arm: <reason>" with MAV_RESULT_FAILED; "PreArm: <reason>" every 30 s while a check fails. false:
    /// 2.x, armed from boot (ARMING_REQUIRE 0), no arming command.
    bool arming_checks = true;
    /// ModeAuto's mission change detector (AP_Mission_ChangeDetector): a change of the current navigation
    /// command or of the next two (DO_JUMP followed) restarts the current one in the WP submode.
    bool mission_change_restart = true;
    /// Where the speed in AUTO comes from.
    enum class AutoSpeed : std::uint8_t {
        /// AR_WPNav: WP_SPEED at every entry into AUTO (and GUIDED, RTL); DO_CHANGE_SPEED changes it in
        /// those modes only; CRUISE_SPEED is not the AUTO speed.
        WpSpeed,
        /// 2.x: CRUISE_SPEED, a new value applying at once; DO_CHANGE_SPEED writes it.
        CruiseSpeed,
    };
    AutoSpeed auto_speed = AutoSpeed::WpSpeed;
    /// S-curve cornering (AR_WPNav since 4.2): the car slows for a turn by its angle and the lateral
    /// acceleration limit, stops where the next leg has no length, at the last waypoint and at a waypoint
    /// with a hold time (which it then holds), and re-plans from standstill when a command restarts.
    bool cornering = true;

    static FirmwareProfile modern();
    static FirmwareProfile rover2();
    static FirmwareProfile of(Firmware f);
    bool operator==(const FirmwareProfile&) const = default;
};

}  // namespace airseg::apmsim
