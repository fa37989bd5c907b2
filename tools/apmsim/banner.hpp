#pragma once
// The banner current ArduPilot sends as STATUSTEXT (GCS_MAVLINK::send_banner() in
// libraries/GCS_MAVLink/GCS_Common.cpp), all MAV_SEVERITY_INFO, in this order: the firmware string
// (THISFIRMWARE " (" GIT_VERSION ")"), the OS line ("ChibiOS: <hash>"), the board's short name with its
// 12-byte unique id (AP_HAL_ChibiOS Util::get_system_id()), the RC output banner ("RCOut: ..."). Rover adds
// no line of its own. The modelled board is a ChibiOS one without an IO co-processor (no "IOMCU:" line) and
// without fast-sampling IMUs (no "IMUn: fast sampling ..." line).
#include <cstdint>
#include <span>
#include <string_view>

namespace airseg::apmsim {

/// MAV_CMD_DO_SEND_BANNER (ardupilotmega.xml): answered ACCEPTED after the banner.
inline constexpr std::uint16_t kCmdDoSendBanner = 42428;

/// The banner of the modern profile, line by line.
std::span<const std::string_view> firmware_banner();

}  // namespace airseg::apmsim
