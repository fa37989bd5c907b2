#include "tools/apmsim/options.hpp"

#include <functional>

#include "cli/command_line.hpp"

namespace airseg::apmsim {

using cli::UsageError;

namespace {

constexpr const char* kUsageHead = R"(usage: airseg-apmsim --link PATH [options]

Simulates an ArduPilot APM:Rover board on a pseudo-terminal. PATH becomes a symlink to the pty slave; open
it as you would open /dev/ttyACM0. The board speaks MAVLink as system 1, component 1
(MAV_TYPE_GROUND_ROVER, MAV_AUTOPILOT_ARDUPILOTMEGA) to any ground station.

Like an APM on USB, the board reboots when a program opens the port (DTR): it goes silent for the boot
delay, then sends "Initialising APM..." and heartbeats in MAV_STATE_CALIBRATING (mode INITIALISING)
for the calibration time, then "Ready to drive." and mode INITIAL_MODE (MANUAL). The modern board then
waits to be armed (ARMING_REQUIRE 1); the rover2 board is armed from the start.

)";

constexpr const char* kUsageTail = R"(
On exit (SIGINT, SIGTERM) the mode history is printed on standard output as one JSON object. SIGUSR1
reboots the board.

Control commands (one per datagram; the reply goes to the sender's bound address):
  state                    position, mode, armed, current item, mission count... as JSON
  modes [N]                mode history (the last N changes) as JSON: [{"t":s,"from":..,"to":..,"cause":..,"seq":..,"count":..}]
                           causes: power on, reboot, command, rc pilot, mission end, rtl end
  reached [FROM [COUNT]]   reached items number FROM on (at most COUNT, 500 by default) as JSON:
                           {"total":N,"first_kept":K,"reached":[{"n":..,"seq":..,"lat":..,"lon":..,..,
                           "leg_s":..,"median_speed":..}]}
  stats                    byte, frame, mission, restarted-command and arming counters as JSON
  speeds [FROM [COUNT]]    changes of the navigation speed number FROM on as JSON:
                           {"total":N,"first_kept":K,"speeds":[{"n":..,"t":s,"speed":..,"cause":..,"seq":..}]}
  rcpilot MODE             the RC pilot flips the mode switch (MANUAL, HOLD, AUTO, ... or a number)
  mode MODE                the board changes mode by itself, as its failsafe would (cause "board")
  reboot [S]               reboot now, or in S simulated seconds
  unplug | replug          remove the pty (the link is gone) / create a new one at PATH
  hbstall S                no heartbeats for S seconds
  loss P [BURST]           set byte loss (in bursts of BURST bytes on average)
  corrupt P                set byte corruption
  ignore-mission on|off    ignore mission protocol messages
  slow MS                  answer requests MS milliseconds late (0: at once)
  param NAME [VALUE]       read or set a parameter
  arm [force] | disarm     arm (the checks run unless forced) or disarm, as MAV_CMD_COMPONENT_ARM_DISARM
  gps lose|fix             the GPS loses or gets its fix (arming in AUTO then fails: no position estimate)
  fail-check REASON...|off an arming check fails with REASON ("PreArm: REASON", "Arm: REASON") / passes
  help
)";

}  // namespace

namespace {

GeoPoint parse_lat_lon(std::string_view option, std::string_view text) {
    const auto comma = text.find(',');
    if (comma == std::string_view::npos) {
        throw UsageError(std::string(option) + ": expected LAT,LON, got '" + std::string(text) + "'");
    }
    return GeoPoint{cli::parse_double(option, text.substr(0, comma), -89, 89),
                    cli::parse_double(option, text.substr(comma + 1), -180, 180)};
}

// The firmware sets defaults (MAVLink version, reached style, mission timers) that the other options
// may then change, wherever --firmware stands on the line: they act after the whole line is read.
void fill_table(cli::OptionTable& table, ApmSimOptions& o,
                std::vector<std::function<void()>>& after_firmware) {
    using namespace cli;
    auto later = [&after_firmware](Apply apply) -> Apply {
        return [&after_firmware, apply = std::move(apply)](std::string_view option, std::string_view text) {
            after_firmware.push_back(
                [apply, option = std::string(option), text = std::string(text)] { apply(option, text); });
        };
    };
    auto later_flag = [&after_firmware](std::function<void()> apply) {
        return [&after_firmware, apply = std::move(apply)] { after_firmware.push_back(apply); };
    };
    table.value("link", "PATH", "symlink to the pty slave (required)", text(o.link_path))
        .value("firmware", "PROFILE",
               "what the board runs (docs/simulators.md, \"Firmware profiles\"): modern: ArduPilot Rover as "
               "today (MAVLink 2, MISSION_ITEM_INT, COMMAND_LONG modes, AUTO resumes, MISSION_ITEM_REACHED); "
               "rover2: APMrover2 2.4x on an APM 2.5 (MAVLink 1 only, float mission items, SET_MODE without "
               "acknowledgement, AUTO restarts at item 1, text-only reached reports, 500 ms re-request and 1 "
               "s patience in uploads) [modern]",
               [&o](std::string_view option, std::string_view v) {
                   const auto f = parse_firmware(v);
                   if (!f) {
                       throw UsageError(std::string(option) + ": expected modern or rover2, got '" +
                                        std::string(v) + "'");
                   }
                   o.sim = RoverSimConfig::for_firmware(*f);
               })
        .value("boot-delay", "S", "silence after a reset, seconds [2]", later(in_seconds(o.sim.boot_delay)))
        .value("calib-time", "S", "calibration time after the silence, seconds [3]",
               later(in_seconds(o.sim.calib_time)))
        .flag("no-reset-on-open", "do not reboot when the port is opened (Pixhawk-style boards)",
              later_flag([&o] { o.sim.reset_on_open = false; }))
        .value("baud", "N",
               "the board's UART rate. A pty moves bytes at any rate, so the simulator reads the rate the "
               "peer set on its end; while it differs, both sides receive noise, as two UARTs at different "
               "rates do [any rate]",
               number(o.baud, 9600, 1500000))
        .value("home", "LAT,LON", "start and home position, degrees [41.2756,1.9866]",
               later([&o](std::string_view option, std::string_view v) {
                   o.sim.home = parse_lat_lon(option, v);
               }))
        .value("home-alt", "M", "home altitude above mean sea level, metres [5]",
               later(number(o.sim.home_alt, -1000, 10000)))
        .value("mission-capacity", "N", "mission items the board holds, home included [150]",
               later(number(o.sim.mission_capacity, 1, 65535)))
        .value("reached-style", "STYLE",
               "both: MISSION_ITEM_REACHED and the STATUSTEXT \"Reached waypoint #N dist Mm\"; text: the "
               "text only, as APM:Rover 2.x firmware does [both]",
               later([&o](std::string_view option, std::string_view v) {
                   if (v == "both") {
                       o.sim.reached_style = ReachedStyle::MessageAndText;
                   } else if (v == "text") {
                       o.sim.reached_style = ReachedStyle::TextOnly;
                   } else {
                       throw UsageError(std::string(option) + ": expected both or text, got '" +
                                        std::string(v) + "'");
                   }
               }))
        .flag("mavlink1", "speak MAVLink 1 (default MAVLink 2; rover2 always does)",
              later_flag([&o] { o.sim.version = mavlink::Version::V1; }))
        .value("param", "NAME=VALUE", "set a parameter before boot (repeatable), e.g. WP_RADIUS=3",
               later([&o](std::string_view option, std::string_view text) {
                   const std::string v(text);
                   const auto eq = v.find('=');
                   if (eq == std::string::npos || eq == 0) {
                       throw UsageError(std::string(option) + ": expected NAME=VALUE, got '" + v + "'");
                   }
                   const std::string name = v.substr(0, eq);
                   if (!ParamTable::for_profile(o.sim.firmware).index_of(name)) {
                       throw UsageError(std::string(option) + ": unknown parameter '" + name +
                                        "' (firmware " + std::string(firmware_name(o.sim.firmware.firmware)) +
                                        ")");
                   }
                   o.params.emplace_back(
                       name, static_cast<float>(parse_double(option, v.substr(eq + 1), -1e9, 1e9)));
               }))
        .value("seed", "N", "seed of the fault generators (deterministic) [1]",
               later(number(o.sim.seed, 0, UINT64_MAX)))
        .value("speedup", "N", "simulated time runs N times faster than real time [1]",
               number(o.speedup, 0.01, 10000))
        // Faults (times are simulated seconds after start):
        .value("loss", "P", "fraction of the bytes lost, each direction", probability(o.faults.loss))
        .value("loss-burst", "N",
               "lose bytes in bursts of N bytes on average (geometric lengths: frames cut short, tails, "
               "whole frames) instead of one by one [1]",
               number(o.faults.loss_burst, 1, 10000))
        .value("corrupt", "P", "probability each byte (either direction) gets a bit flipped",
               probability(o.faults.corrupt))
        .value("hb-stall", "START:DUR", "no heartbeats from START for DUR seconds (repeatable)",
               windows(o.hb_stalls))
        .value("reboot-at", "S", "reboot at S", in_seconds(o.reboot_at))
        .value("unplug", "START:DUR", "remove the pty at START, plug a new one in after DUR (repeatable)",
               windows(o.unplugs))
        .flag("ignore-mission", "ignore every mission protocol message",
              [&o] { o.faults.ignore_mission = true; })
        .value("slow", "MS", "answer every request MS milliseconds late", in_milliseconds(o.faults.slow))
        .value("control", "PATH", "Unix datagram socket taking run-time commands (below)",
               text(o.control_path))
        .flag("quiet", "no event lines on standard error", [&o] { o.quiet = true; })
        .help_and_version(false);
}

}  // namespace

std::string usage() {
    ApmSimOptions unused;
    std::vector<std::function<void()>> after_firmware;
    cli::OptionTable table("Options");
    fill_table(table, unused, after_firmware);
    return std::string(kUsageHead) + cli::describe(table) + kUsageTail;
}

std::optional<ApmSimOptions> parse_options(const std::vector<std::string>& args) {
    ApmSimOptions o;
    std::vector<std::function<void()>> after_firmware;
    cli::OptionTable table;
    fill_table(table, o, after_firmware);
    cli::parse(args, table);
    if (table.help_requested()) {
        return std::nullopt;
    }
    for (const auto& apply : after_firmware) {
        apply();
    }
    if (o.link_path.empty()) {
        throw UsageError("--link PATH is required");
    }
    if (const auto errors = RoverSimConfig::validate(o.sim); !errors.empty()) {
        throw UsageError(errors.front());
    }
    return o;
}

}  // namespace airseg::apmsim
