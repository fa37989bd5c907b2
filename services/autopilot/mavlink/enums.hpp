#pragma once
// Values of the MAVLink enums that airseg's autopilot driver and simulator read and send (common.xml;
// MAV_AUTOPILOT_ARDUPILOTMEGA from the same list). Names follow the specification's, in the project's
// kCamelCase: MAV_CMD_DO_SET_MODE is kCmdDoSetMode, MAV_RESULT_ACCEPTED is kResultAccepted.
#include <cstdint>

namespace airseg::mavlink {

// MAV_CMD
inline constexpr std::uint16_t kCmdNavWaypoint = 16;
inline constexpr std::uint16_t kCmdNavLoiterUnlim = 17;
inline constexpr std::uint16_t kCmdNavLoiterTime = 19;
inline constexpr std::uint16_t kCmdDoSetMode = 176;
inline constexpr std::uint16_t kCmdDoJump = 177;
inline constexpr std::uint16_t kCmdDoChangeSpeed = 178;
inline constexpr std::uint16_t kCmdDoSetHome = 179;
inline constexpr std::uint16_t kCmdDoSetParameter = 180;
inline constexpr std::uint16_t kCmdDoSetRelay = 181;
inline constexpr std::uint16_t kCmdDoRepeatRelay = 182;
inline constexpr std::uint16_t kCmdDoSetServo = 183;
inline constexpr std::uint16_t kCmdDoRepeatServo = 184;
inline constexpr std::uint16_t kCmdDoSetMissionCurrent = 224;
inline constexpr std::uint16_t kCmdPreflightCalibration = 241;
inline constexpr std::uint16_t kCmdPreflightRebootShutdown = 246;
inline constexpr std::uint16_t kCmdMissionStart = 300;
inline constexpr std::uint16_t kCmdComponentArmDisarm = 400;
inline constexpr std::uint16_t kCmdGetHomePosition = 410;
inline constexpr std::uint16_t kCmdSetMessageInterval = 511;
inline constexpr std::uint16_t kCmdRequestMessage = 512;
inline constexpr std::uint16_t kCmdRequestAutopilotCapabilities = 520;

// MAV_RESULT (COMMAND_ACK)
inline constexpr std::uint8_t kResultAccepted = 0;
inline constexpr std::uint8_t kResultTemporarilyRejected = 1;
inline constexpr std::uint8_t kResultDenied = 2;
inline constexpr std::uint8_t kResultUnsupported = 3;
inline constexpr std::uint8_t kResultFailed = 4;
inline constexpr std::uint8_t kResultInProgress = 5;
/// MAV_RESULT_<name> without the prefix ("ACCEPTED", "FAILED"...), "unknown" past CANCELLED.
inline const char* result_name(std::uint8_t r) {
    constexpr const char* kNames[] = {"ACCEPTED", "TEMPORARILY_REJECTED", "DENIED",   "UNSUPPORTED",
                                      "FAILED",   "IN_PROGRESS",          "CANCELLED"};
    return r < sizeof kNames / sizeof kNames[0] ? kNames[r] : "unknown";
}

// MAV_MISSION_RESULT (MISSION_ACK)
inline constexpr std::uint8_t kMissionAccepted = 0;
inline constexpr std::uint8_t kMissionError = 1;
inline constexpr std::uint8_t kMissionUnsupportedFrame = 2;
inline constexpr std::uint8_t kMissionUnsupported = 3;
inline constexpr std::uint8_t kMissionNoSpace = 4;
inline constexpr std::uint8_t kMissionInvalidSequence = 13;
inline constexpr std::uint8_t kMissionDenied = 14;
inline constexpr std::uint8_t kMissionOperationCancelled = 15;

// MAV_MISSION_TYPE
inline constexpr std::uint8_t kMissionTypeMission = 0;

// MAV_FRAME
inline constexpr std::uint8_t kFrameGlobal = 0;
inline constexpr std::uint8_t kFrameMission = 2;
inline constexpr std::uint8_t kFrameGlobalRelativeAlt = 3;
inline constexpr std::uint8_t kFrameGlobalInt = 5;
inline constexpr std::uint8_t kFrameGlobalRelativeAltInt = 6;

// MAV_TYPE, MAV_AUTOPILOT
inline constexpr std::uint8_t kMavTypeGroundRover = 10;
inline constexpr std::uint8_t kMavAutopilotArdupilotmega = 3;

// MAV_MODE_FLAG (HEARTBEAT base_mode)
inline constexpr std::uint8_t kModeFlagCustomModeEnabled = 1;
inline constexpr std::uint8_t kModeFlagAutoEnabled = 4;
inline constexpr std::uint8_t kModeFlagGuidedEnabled = 8;
inline constexpr std::uint8_t kModeFlagStabilizeEnabled = 16;
inline constexpr std::uint8_t kModeFlagManualInputEnabled = 64;
inline constexpr std::uint8_t kModeFlagSafetyArmed = 128;

// MAV_STATE (HEARTBEAT system_status)
inline constexpr std::uint8_t kMavStateUninit = 0;
inline constexpr std::uint8_t kMavStateBoot = 1;
inline constexpr std::uint8_t kMavStateCalibrating = 2;
inline constexpr std::uint8_t kMavStateStandby = 3;
inline constexpr std::uint8_t kMavStateActive = 4;
inline constexpr std::uint8_t kMavStatePoweroff = 7;

// MAV_SEVERITY (STATUSTEXT)
inline constexpr std::uint8_t kSeverityCritical = 2;
inline constexpr std::uint8_t kSeverityWarning = 4;
inline constexpr std::uint8_t kSeverityInfo = 6;

}  // namespace airseg::mavlink
