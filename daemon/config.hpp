#pragma once
// The daemon's configuration: one struct per component with its defaults. The YAML key of each field is
// written next to it; the schema (config_schema.cpp) is the single place that maps keys to fields, with
// types, ranges and documentation.
#include <chrono>
#include <map>
#include <string>
#include <vector>

#include "services/groundlink/transport/radio_profile.hpp"

namespace airseg::daemon {

using std::chrono::milliseconds;

struct StatusConfig {
    std::string socket = "/run/airseg/status.sock";  // status.socket
    unsigned socket_mode = 0660;                     // status.socket_mode (octal)
};

struct AutopilotConfig {
    std::string board = "apm2";             // autopilot.board: apm2 | pixhawk
    std::string port = "/dev/ttyACM0";      // autopilot.port
    int baud = 115200;                      // autopilot.baud
    std::vector<int> bauds;                 // autopilot.bauds: tried in turn when non-empty
    milliseconds baud_probe{3'000};         // autopilot.baud_probe: time for a valid frame at one rate
    std::string gcs_heartbeat = "gcs";      // autopilot.gcs_heartbeat: gcs | onboard | off
    std::string reset_on_open = "auto";     // autopilot.reset_on_open: auto (= board is apm2) | true | false
    milliseconds reconnect_min{500};        // autopilot.reconnect_min
    milliseconds reconnect_max{10'000};     // autopilot.reconnect_max
    milliseconds boot_timeout{30'000};      // autopilot.boot_timeout
    milliseconds heartbeat_timeout{3'000};  // autopilot.heartbeat_timeout
    milliseconds mode_timeout{1'500};       // autopilot.mode_timeout
    std::string arming = "auto";            // autopilot.arming: auto | never
    std::map<std::string, double> params;   // autopilot.params: {NAME: value}
    std::map<std::string, double> streams;  // autopilot.streams: {position: 4, ...}; empty = board's
    std::map<std::string, double>
        message_rates;                  // autopilot.message_rates: {ATTITUDE: 10, ...}; empty = board's
    double rc_override_rate_hz = 10.0;  // autopilot.rc_override.rate_hz
    milliseconds rc_override_input_timeout{500};               // autopilot.rc_override.input_timeout
    bool tlog_enabled = false;                                 // autopilot.tlog.enabled
    std::string tlog_path = "/var/log/airseg/autopilot.tlog";  // autopilot.tlog.path
    long long tlog_max_bytes = 64ll << 20;                     // autopilot.tlog.max_bytes
    int tlog_keep = 4;                                         // autopilot.tlog.keep
    std::string gcs_endpoint_udp;  // autopilot.gcs_endpoint.udp: ADDRESS:PORT for ground stations; "" = off
    std::string gcs_endpoint_tcp;  // autopilot.gcs_endpoint.tcp: ADDRESS:PORT for ground stations; "" = off
    std::string reset_line;        // autopilot.reset.line: name or chip:offset; "" = none
    milliseconds reset_unresponsive_timeout{20'000};  // autopilot.reset.unresponsive_timeout
    int reset_max_pulses = 3;                         // autopilot.reset.max_pulses
};

struct GroundlinkConfig {
    std::string mode = "single";                      // groundlink.mode: single | split | redundant | udp
    std::vector<std::string> ports{"/dev/ttyUSB0"};   // groundlink.ports: one or two serial devices
    int baud = 57600;                                 // groundlink.baud
    std::string key_file = "/etc/airseg/ground.key";  // groundlink.key_file: empty = no authentication
    bool insecure = false;                            // groundlink.insecure: commands without a key
    milliseconds reconnect_min{500};                  // groundlink.reconnect_min
    milliseconds reconnect_max{10'000};               // groundlink.reconnect_max
    std::string udp_bind = "127.0.0.1";               // groundlink.udp.bind
    int udp_port = 14650;                             // groundlink.udp.port
    std::string udp_remote;                           // groundlink.udp.remote: empty = answer the last sender
    int udp_remote_port = 0;                          // groundlink.udp.remote_port
    std::string monitor_key_file;                     // groundlink.monitor_key_file: empty = no monitor role
    std::map<std::string, double> telemetry_rates{{"vehicle", 2.0}, {"link_stats", 1.0}};  // .telemetry.rates
    double telemetry_budget_share = 0.25;  // groundlink.telemetry.budget_share
    double telemetry_min_hz = 0.2;         // groundlink.telemetry.min_hz
    bool mavlink_forward_enabled = false;  // groundlink.mavlink_forward.enabled
    double mavlink_forward_budget = 0;  // groundlink.mavlink_forward.budget_bytes_per_s: 0 = 30 % of the link
    std::map<std::string, double>
        mavlink_forward_rates;  // groundlink.mavlink_forward.rates: name or id -> Hz
    // groundlink.radio.*: air_speed, ecc, packet, packet_overhead, turnaround, duplex, buffer
    groundlink::RadioProfile radio;
};

struct StatusLedConfig {
    std::string line;         // status_led.line: GPIO line name or chip:offset; "" = no LED
    bool active_low = false;  // status_led.active_low
};

struct FlightplanConfig {
    int window = 5;                        // flightplan.window: ring slots on the autopilot (>= 3)
    std::string vehicle = "rover";         // flightplan.vehicle: profile of plans without `vehicle`
    milliseconds request_timeout{5'000};   // flightplan.request_timeout
    int retries = 3;                       // flightplan.retries
    bool resume_after_reboot = true;       // flightplan.resume_after_reboot
    bool fsync = true;                     // flightplan.fsync
    milliseconds command_timeout{30'000};  // flightplan.command_timeout
};

struct Config {
    int threads = 1;                            // threads: 0 = one per core
    std::string log_level = "info";             // log_level
    std::string state_dir = "/var/lib/airseg";  // state_dir
    StatusConfig status;
    AutopilotConfig autopilot;
    GroundlinkConfig groundlink;
    StatusLedConfig status_led;
    FlightplanConfig flightplan;
};

}  // namespace airseg::daemon
