#pragma once
// airsegctl's commands that live on the radio link: watch (pushed telemetry in a screen refreshed in
// place), log (events and autopilot texts as they come) and joystick (operator input at a fixed rate).
#include <chrono>
#include <string>
#include <vector>

#include "client/vehicle_link.hpp"

namespace airseg::client {

struct LiveOptions {
    bool json = false;
    std::chrono::milliseconds timeout{5000};
    std::chrono::milliseconds refresh{500};
    /// Stop after this long (0: until Ctrl-C); for scripts and tests.
    std::chrono::milliseconds duration{0};
    /// watch --note: lines shown under the live view on every refresh (the demo's hints stay on screen).
    std::vector<std::string> notes;
    /// watch and log --debug: also the events that say nothing new (groundside/event_wording.hpp), as the
    /// vehicle sent them.
    bool debug = false;
};

/// Exit codes as everywhere in airsegctl: 0 done, 1 refused, 2 usage, 3 no link.
int run_radio_watch(VehicleLink& radio, const LiveOptions& options);
int run_log(VehicleLink& radio, const LiveOptions& options);

struct JoystickOptions {
    std::string device;  // /dev/input/jsN; empty = keyboard
    double rate_hz = 10;
};
int run_joystick(VehicleLink& radio, const LiveOptions& options, const JoystickOptions& joystick);

/// The --note lines as shown under a live view (empty without notes).
std::string notes_text(const LiveOptions& options);

/// Installs SIGINT/SIGTERM handlers that end the live commands cleanly.
void install_stop_handlers();
bool stop_requested();

}  // namespace airseg::client
