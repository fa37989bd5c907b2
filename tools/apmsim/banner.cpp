// RoverSim: the firmware's banner. Current ArduPilot sends it on every PARAM_REQUEST_LIST, before the
// parameters ("requesting parameters is a convenient way to get extra information":
// GCS_MAVLINK::handle_param_request_list() in libraries/GCS_MAVLink/GCS_Param.cpp), and on
// MAV_CMD_DO_SEND_BANNER (handle_command_do_send_banner()). The rover2 profile sends none.
#include "tools/apmsim/banner.hpp"

#include <array>

#include "services/autopilot/mavlink/enums.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

std::span<const std::string_view> firmware_banner() {
    static constexpr std::array<std::string_view, 4> kLines{
        "ArduRover V4.6.2 (5d9e3f1c)",
        "ChibiOS: 6a85082c",
        "MatekH743 001E0028 3130510F 37383538",
        "RCOut: PWM:1-12",
    };
    return kLines;
}

void RoverSim::send_banner() {
    if (rover2_telemetry()) {
        return;
    }
    for (const auto line : firmware_banner()) {
        text(mavlink::kSeverityInfo, line);
    }
}

}  // namespace airseg::apmsim
