#pragma once
// Turns the autopilot.* keys of the daemon's configuration into the AutopilotService's configuration,
// starting from the board's defaults, and lists every problem the autopilot layer finds in the result (each
// message starts with the key it is about, "autopilot.boot_timeout: ...").
#include <optional>
#include <string>
#include <vector>

#include "daemon/config.hpp"
#include "services/autopilot/autopilot_service.hpp"
#include "services/groundlink/frame_forwarder.hpp"

namespace airseg::daemon {

struct AutopilotSetup {
    autopilot::AutopilotServiceConfig service;
    std::optional<hal::GpioLineRequest> status_led;  // status_led.*: the LED line, when configured
    std::vector<std::string> problems;
};

AutopilotSetup autopilot_setup(const Config& config);

/// groundlink.mavlink_forward as the ground-link service takes it: rates by message id (a key is a MAVLink
/// message name this daemon knows, or a message id; "default" sets the rate of the others). Each problem
/// starts with its key.
struct ForwardSetup {
    groundlink::FrameForwarderConfig config;
    std::vector<std::string> problems;
};
ForwardSetup mavlink_forward_setup(const Config& config);

/// "autopilot.boot_timeout" (or "status_led.line") from "autopilot.boot_timeout: 200 s is outside ..."; empty
/// when the message does not start with a key.
std::string problem_key(const std::string& problem);

}  // namespace airseg::daemon
