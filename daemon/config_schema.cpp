#include "daemon/config_schema.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "base/utf8.hpp"
#include "daemon/duration.hpp"

namespace airseg::daemon {
namespace {

/// A value as an error message echoes it: cut, so that a 10 MB value is not repeated whole.
std::string scalar_text(const YAML::Node& node) {
    return node.IsScalar() ? excerpt(node.Scalar()) : std::string("(not a scalar)");
}

template <class Ref>
KeySpec integer(std::string path, Ref ref, long long min, long long max, std::string doc,
                bool runtime = false) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = fmt::format("integer {}..{}", min, max);
    spec.doc = std::move(doc);
    spec.runtime = runtime;
    spec.apply = [ref, min, max](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        long long v = 0;
        if (!node.IsScalar() || !YAML::convert<long long>::decode(node, v)) {
            return fmt::format("expected an integer, got '{}'", scalar_text(node));
        }
        if (v < min || v > max) {
            return fmt::format("{} is out of range {}..{}", v, min, max);
        }
        ref(c) = static_cast<std::remove_reference_t<decltype(ref(c))>>(v);
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) { return std::to_string(ref(const_cast<Config&>(c))); };
    return spec;
}

template <class Ref>
KeySpec octal_mode(std::string path, Ref ref, std::string doc) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = "octal file mode, e.g. \"0660\"";
    spec.doc = std::move(doc);
    spec.apply = [ref](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        const std::string text = node.IsScalar() ? node.Scalar() : "";
        if (text.empty() || text.size() > 4 || text.find_first_not_of("01234567") != std::string::npos) {
            return fmt::format("expected an octal mode like \"0660\", got '{}'", scalar_text(node));
        }
        ref(c) = static_cast<unsigned>(std::stoul(text, nullptr, 8));
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) { return fmt::format("\"{:04o}\"", ref(const_cast<Config&>(c))); };
    return spec;
}

template <class Ref>
KeySpec boolean(std::string path, Ref ref, std::string doc, bool runtime = false) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = "boolean";
    spec.doc = std::move(doc);
    spec.runtime = runtime;
    spec.apply = [ref](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        bool v = false;
        if (!node.IsScalar() || !YAML::convert<bool>::decode(node, v)) {
            return fmt::format("expected true or false, got '{}'", scalar_text(node));
        }
        ref(c) = v;
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) { return ref(const_cast<Config&>(c)) ? "true" : "false"; };
    return spec;
}

template <class Ref>
KeySpec string(std::string path, Ref ref, std::string doc, bool allow_empty, bool runtime = false) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = allow_empty ? "string (may be empty)" : "string";
    spec.doc = std::move(doc);
    spec.runtime = runtime;
    spec.apply = [ref, allow_empty](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        if (node.IsNull() && allow_empty) {
            ref(c).clear();
            return std::nullopt;
        }
        if (!node.IsScalar()) {
            return "expected a string";
        }
        if (node.Scalar().empty() && !allow_empty) {
            return "must not be empty";
        }
        ref(c) = node.Scalar();
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) { return fmt::format("\"{}\"", ref(const_cast<Config&>(c))); };
    return spec;
}

template <class Ref>
KeySpec choice(std::string path, Ref ref, std::vector<std::string> choices, std::string doc,
               bool runtime = false) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = fmt::format("one of {}", fmt::join(choices, " | "));
    spec.doc = std::move(doc);
    spec.runtime = runtime;
    spec.apply = [ref, choices](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        if (!node.IsScalar() || std::find(choices.begin(), choices.end(), node.Scalar()) == choices.end()) {
            return fmt::format("expected one of {}, got '{}'", fmt::join(choices, ", "), scalar_text(node));
        }
        ref(c) = node.Scalar();
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) { return ref(const_cast<Config&>(c)); };
    return spec;
}

template <class Ref>
KeySpec duration(std::string path, Ref ref, milliseconds min, milliseconds max, std::string doc,
                 bool runtime = false) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = fmt::format("duration {}..{}", format_duration(min), format_duration(max));
    spec.doc = std::move(doc);
    spec.runtime = runtime;
    spec.apply = [ref, min, max](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        auto d = node.IsScalar() ? parse_duration(node.Scalar()) : std::nullopt;
        if (!d) {
            return fmt::format("expected a duration like 1500ms, 3s or 2m, got '{}'", scalar_text(node));
        }
        if (*d < min || *d > max) {
            return fmt::format("{} is out of range {}..{}", format_duration(*d), format_duration(min),
                               format_duration(max));
        }
        ref(c) = *d;
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) {
        return format_duration(std::chrono::duration_cast<milliseconds>(ref(const_cast<Config&>(c))));
    };
    return spec;
}

/// A boolean spelled as one of two words, e.g. duplex: half | full.
template <class Ref>
KeySpec two_words(std::string path, Ref ref, std::string when_true, std::string when_false, std::string doc) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = fmt::format("one of {} | {}", when_true, when_false);
    spec.doc = std::move(doc);
    spec.apply = [ref, when_true, when_false](const YAML::Node& node,
                                              Config& c) -> std::optional<std::string> {
        if (node.IsScalar() && node.Scalar() == when_true) {
            ref(c) = true;
        } else if (node.IsScalar() && node.Scalar() == when_false) {
            ref(c) = false;
        } else {
            return fmt::format("expected {} or {}, got '{}'", when_true, when_false, scalar_text(node));
        }
        return std::nullopt;
    };
    spec.show = [ref, when_true, when_false](const Config& c) {
        return ref(const_cast<Config&>(c)) ? when_true : when_false;
    };
    return spec;
}

template <class Ref>
KeySpec string_list(std::string path, Ref ref, std::size_t min_items, std::size_t max_items,
                    std::string doc) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = fmt::format("list of {}..{} strings", min_items, max_items);
    spec.doc = std::move(doc);
    spec.apply = [ref, min_items, max_items](const YAML::Node& node,
                                             Config& c) -> std::optional<std::string> {
        if (!node.IsSequence()) {
            return "expected a list, e.g. [/dev/ttyUSB0, /dev/ttyUSB1]";
        }
        if (node.size() < min_items || node.size() > max_items) {
            return fmt::format("expected {} to {} entries, got {}", min_items, max_items, node.size());
        }
        std::vector<std::string> out;
        for (const auto& item : node) {
            if (!item.IsScalar() || item.Scalar().empty()) {
                return "every entry must be a non-empty string";
            }
            out.push_back(item.Scalar());
        }
        ref(c) = std::move(out);
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) {
        return fmt::format("[{}]", fmt::join(ref(const_cast<Config&>(c)), ", "));
    };
    return spec;
}

template <class Ref>
KeySpec number(std::string path, Ref ref, double min, double max, std::string doc, bool runtime = false) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.runtime = runtime;
    spec.type_name = fmt::format("number {}..{}", min, max);
    spec.doc = std::move(doc);
    spec.apply = [ref, min, max](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        double v = 0;
        if (!node.IsScalar() || !YAML::convert<double>::decode(node, v)) {
            return fmt::format("expected a number, got '{}'", scalar_text(node));
        }
        if (!(v >= min && v <= max)) {
            return fmt::format("{} is out of range {}..{}", v, min, max);
        }
        ref(c) = v;
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) { return fmt::format("{}", ref(const_cast<Config&>(c))); };
    return spec;
}

/// A mapping of names to numbers, e.g. {WP_RADIUS: 2, CRUISE_SPEED: 1.5}. `names` empty = any name;
/// otherwise only those. `whole` requires whole numbers >= 0.
template <class Ref>
KeySpec number_map(std::string path, Ref ref, std::vector<std::string> names, bool whole, std::string doc,
                   bool runtime = false) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.runtime = runtime;
    spec.type_name = names.empty() ? "mapping NAME: number"
                                   : fmt::format("mapping of {} to {}", fmt::join(names, " | "),
                                                 whole ? "whole numbers >= 0" : "numbers");
    spec.doc = std::move(doc);
    spec.apply = [ref, names, whole](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        if (node.IsNull()) {
            ref(c).clear();
            return std::nullopt;
        }
        if (!node.IsMap()) {
            return "expected a mapping, e.g. {NAME: 1.5}";
        }
        std::map<std::string, double> out;
        for (const auto& entry : node) {
            if (!entry.first.IsScalar() || entry.first.Scalar().empty()) {
                return "every name must be a non-empty plain string";
            }
            const std::string name = entry.first.Scalar();
            if (!names.empty() && std::find(names.begin(), names.end(), name) == names.end()) {
                return fmt::format("unknown name '{}' (one of {})", excerpt(name), fmt::join(names, ", "));
            }
            double v = 0;
            if (!entry.second.IsScalar() || !YAML::convert<double>::decode(entry.second, v) ||
                !std::isfinite(v)) {
                return fmt::format("{}: expected a number, got '{}'", excerpt(name),
                                   scalar_text(entry.second));
            }
            if (whole && (v < 0 || v != std::floor(v))) {
                return fmt::format("{}: expected a whole number >= 0, got {}", excerpt(name), v);
            }
            if (!out.emplace(name, v).second) {
                return fmt::format("{} is given twice", excerpt(name));
            }
        }
        ref(c) = std::move(out);
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) {
        std::vector<std::string> parts;
        for (const auto& [name, value] : ref(const_cast<Config&>(c))) {
            parts.push_back(fmt::format("{}: {}", name, value));
        }
        return fmt::format("{{{}}}", fmt::join(parts, ", "));
    };
    return spec;
}

const std::vector<int> kStandardBauds{9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 921600};

std::optional<std::string> check_baud(long long v) {
    if (std::find(kStandardBauds.begin(), kStandardBauds.end(), v) == kStandardBauds.end()) {
        return fmt::format("{} is not a supported baud rate (one of {})", v, fmt::join(kStandardBauds, ", "));
    }
    return std::nullopt;
}

template <class Ref>
KeySpec baud(std::string path, Ref ref, std::string doc) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = "baud rate";
    spec.doc = std::move(doc);
    spec.apply = [ref](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        long long v = 0;
        if (!node.IsScalar() || !YAML::convert<long long>::decode(node, v)) {
            return fmt::format("expected a baud rate, got '{}'", scalar_text(node));
        }
        if (auto err = check_baud(v)) {
            return err;
        }
        ref(c) = static_cast<int>(v);
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) { return std::to_string(ref(const_cast<Config&>(c))); };
    return spec;
}

template <class Ref>
KeySpec baud_list(std::string path, Ref ref, std::string doc) {
    KeySpec spec;
    spec.path = std::move(path);
    spec.type_name = "list of baud rates";
    spec.doc = std::move(doc);
    spec.apply = [ref](const YAML::Node& node, Config& c) -> std::optional<std::string> {
        if (!node.IsSequence()) {
            return "expected a list of baud rates, e.g. [115200, 57600]";
        }
        std::vector<int> out;
        for (const auto& item : node) {
            long long v = 0;
            if (!item.IsScalar() || !YAML::convert<long long>::decode(item, v)) {
                return fmt::format("expected a baud rate, got '{}'", scalar_text(item));
            }
            if (auto err = check_baud(v)) {
                return err;
            }
            out.push_back(static_cast<int>(v));
        }
        ref(c) = std::move(out);
        return std::nullopt;
    };
    spec.show = [ref](const Config& c) {
        return fmt::format("[{}]", fmt::join(ref(const_cast<Config&>(c)), ", "));
    };
    return spec;
}

std::vector<KeySpec> build_schema() {
    using std::chrono::hours;
    using std::chrono::seconds;
    std::vector<KeySpec> s;
    // General
    s.push_back(integer(
        "threads", [](Config& c) -> int& { return c.threads; }, 0, 64,
        "threads running the services; 0 = one per CPU core"));
    s.push_back(choice(
        "log_level", [](Config& c) -> std::string& { return c.log_level; },
        {"trace", "debug", "info", "warn", "error", "critical", "off"}, "least severe log level written",
        true));
    s.push_back(string(
        "state_dir", [](Config& c) -> std::string& { return c.state_dir; },
        "directory for persistent state (flight plan and progress)", false));
    // Status
    s.push_back(string(
        "status.socket", [](Config& c) -> std::string& { return c.status.socket; },
        "Unix socket serving the status document and on-board commands", false));
    s.push_back(octal_mode(
        "status.socket_mode", [](Config& c) -> unsigned& { return c.status.socket_mode; },
        "permissions of the status socket"));
    // Autopilot
    s.push_back(choice(
        "autopilot.board", [](Config& c) -> std::string& { return c.autopilot.board; }, {"apm2", "pixhawk"},
        "autopilot board family"));
    s.push_back(string(
        "autopilot.port", [](Config& c) -> std::string& { return c.autopilot.port; },
        "serial device of the autopilot", false));
    s.push_back(baud(
        "autopilot.baud", [](Config& c) -> int& { return c.autopilot.baud; },
        "baud rate of the autopilot port"));
    s.push_back(baud_list(
        "autopilot.bauds", [](Config& c) -> std::vector<int>& { return c.autopilot.bauds; },
        "baud rates tried in turn (the first that yields a valid frame is kept); empty = baud"));
    s.push_back(duration(
        "autopilot.baud_probe", [](Config& c) -> milliseconds& { return c.autopilot.baud_probe; },
        milliseconds(0), hours(1),
        "time given to each rate of autopilot.bauds for a valid frame (with reset_on_open: more than the "
        "boot "
        "delay)"));
    s.push_back(choice(
        "autopilot.reset_on_open", [](Config& c) -> std::string& { return c.autopilot.reset_on_open; },
        {"auto", "true", "false"},
        "the board reboots when its port is opened; auto = true for apm2 (USB), false for pixhawk"));
    s.push_back(choice(
        "autopilot.gcs_heartbeat", [](Config& c) -> std::string& { return c.autopilot.gcs_heartbeat; },
        {"gcs", "onboard", "off"},
        "our 1 Hz HEARTBEAT to the autopilot, as MAV_TYPE_GCS or MAV_TYPE_ONBOARD_CONTROLLER (ArduPilot's "
        "GCS "
        "failsafe counts heartbeats from SYSID_MYGCS, 255, our system id), or none"));
    s.push_back(duration(
        "autopilot.reconnect_min", [](Config& c) -> milliseconds& { return c.autopilot.reconnect_min; },
        milliseconds(10), seconds(60), "first retry delay after the port could not be opened or was lost"));
    s.push_back(duration(
        "autopilot.reconnect_max", [](Config& c) -> milliseconds& { return c.autopilot.reconnect_max; },
        milliseconds(10), hours(1), "longest retry delay (the delay doubles up to this)"));
    // Wide ranges here: AutopilotConfig::validate() owns the limits and reports them with the key.
    s.push_back(duration(
        "autopilot.boot_timeout", [](Config& c) -> milliseconds& { return c.autopilot.boot_timeout; },
        milliseconds(0), hours(1), "longest time from the open to READY before the link is reported failed"));
    s.push_back(duration(
        "autopilot.heartbeat_timeout",
        [](Config& c) -> milliseconds& { return c.autopilot.heartbeat_timeout; }, milliseconds(0), hours(1),
        "the link is down after this long without a heartbeat"));
    s.push_back(duration(
        "autopilot.mode_timeout", [](Config& c) -> milliseconds& { return c.autopilot.mode_timeout; },
        milliseconds(0), hours(1), "wait for the autopilot to confirm a mode change, per attempt"));
    s.push_back(choice(
        "autopilot.arming", [](Config& c) -> std::string& { return c.autopilot.arming; }, {"auto", "never"},
        "auto: a request for WAYPOINT_NAVIGATION (a plan starting or resuming) or MANUAL_NAVIGATION arms a "
        "board that is not armed, never forcing; never: airsegd never arms (the RC transmitter or a ground "
        "station does). airsegd never disarms"));
    s.push_back(number_map(
        "autopilot.params", [](Config& c) -> std::map<std::string, double>& { return c.autopilot.params; },
        {}, false, "autopilot parameters written (and read back) on every connection"));
    s.push_back(number_map(
        "autopilot.streams", [](Config& c) -> std::map<std::string, double>& { return c.autopilot.streams; },
        {"raw_sensors", "extended_status", "rc_channels", "position", "extra1", "extra2", "extra3"}, true,
        "telemetry stream rates in Hz (REQUEST_DATA_STREAM boards); empty = the board's defaults"));
    s.push_back(number_map(
        "autopilot.message_rates",
        [](Config& c) -> std::map<std::string, double>& { return c.autopilot.message_rates; }, {}, false,
        "per-message rates in Hz by MAVLink name (SET_MESSAGE_INTERVAL boards); 0 stops a message; empty = "
        "the board's defaults"));
    s.push_back(number(
        "autopilot.rc_override.rate_hz", [](Config& c) -> double& { return c.autopilot.rc_override_rate_hz; },
        0, 1000, "rate of RC override frames while the ground joystick drives"));
    s.push_back(duration(
        "autopilot.rc_override.input_timeout",
        [](Config& c) -> milliseconds& { return c.autopilot.rc_override_input_timeout; }, milliseconds(0),
        hours(1), "joystick input older than this releases the override (the vehicle stops)"));
    s.push_back(boolean(
        "autopilot.tlog.enabled", [](Config& c) -> bool& { return c.autopilot.tlog_enabled; },
        "record every MAVLink frame to a .tlog flight recorder"));
    s.push_back(string(
        "autopilot.tlog.path", [](Config& c) -> std::string& { return c.autopilot.tlog_path; },
        "the .tlog file; rotated files are PATH.1, PATH.2, ...", false));
    s.push_back(integer(
        "autopilot.tlog.max_bytes", [](Config& c) -> long long& { return c.autopilot.tlog_max_bytes; },
        64 * 1024, 1ll << 40, "size at which the .tlog is rotated"));
    s.push_back(integer(
        "autopilot.tlog.keep", [](Config& c) -> int& { return c.autopilot.tlog_keep; }, 0, 100,
        "rotated .tlog files kept"));
    s.push_back(string(
        "autopilot.gcs_endpoint.udp", [](Config& c) -> std::string& { return c.autopilot.gcs_endpoint_udp; },
        "ADDRESS:PORT where ground stations reach the autopilot through airsegd over UDP (e.g. "
        "0.0.0.0:14550); "
        "empty = off",
        true));
    s.push_back(string(
        "autopilot.gcs_endpoint.tcp", [](Config& c) -> std::string& { return c.autopilot.gcs_endpoint_tcp; },
        "ADDRESS:PORT where ground stations reach the autopilot through airsegd over TCP (e.g. "
        "0.0.0.0:5760); "
        "empty = off",
        true));
    s.push_back(string(
        "autopilot.reset.line", [](Config& c) -> std::string& { return c.autopilot.reset_line; },
        "GPIO line pulsed to reset an unresponsive autopilot: a line name or CHIP:OFFSET; empty = none",
        true));
    s.push_back(duration(
        "autopilot.reset.unresponsive_timeout",
        [](Config& c) -> milliseconds& { return c.autopilot.reset_unresponsive_timeout; }, milliseconds(0),
        hours(1),
        "the autopilot counts as unresponsive after this long with the port open and no heartbeat"));
    s.push_back(integer(
        "autopilot.reset.max_pulses", [](Config& c) -> int& { return c.autopilot.reset_max_pulses; }, 0, 1000,
        "reset pulses tried before giving up (0 = never pulse)"));
    // Status LED
    s.push_back(string(
        "status_led.line", [](Config& c) -> std::string& { return c.status_led.line; },
        "GPIO line of the status LED (booting / ready / ground link up / fault): a line name or CHIP:OFFSET; "
        "empty = none",
        true));
    s.push_back(boolean(
        "status_led.active_low", [](Config& c) -> bool& { return c.status_led.active_low; },
        "the LED lights when its line is electrically low"));
    // Ground link
    s.push_back(choice(
        "groundlink.mode", [](Config& c) -> std::string& { return c.groundlink.mode; },
        {"single", "split", "redundant", "udp"}, "how the ground radios are used"));
    s.push_back(string_list(
        "groundlink.ports", [](Config& c) -> std::vector<std::string>& { return c.groundlink.ports; }, 1, 2,
        "serial devices of the ground radios (two for split and redundant)"));
    s.push_back(baud(
        "groundlink.baud", [](Config& c) -> int& { return c.groundlink.baud; },
        "baud rate of the ground radio ports"));
    s.push_back(string(
        "groundlink.key_file", [](Config& c) -> std::string& { return c.groundlink.key_file; },
        "pre-shared key file (mode 0600) authenticating every frame; empty = none", true));
    s.push_back(boolean(
        "groundlink.insecure", [](Config& c) -> bool& { return c.groundlink.insecure; },
        "without key_file, accept commands from an unauthenticated ground (false: refuse them)"));
    s.push_back(duration(
        "groundlink.reconnect_min", [](Config& c) -> milliseconds& { return c.groundlink.reconnect_min; },
        milliseconds(10), seconds(60),
        "first retry delay after a radio port could not be opened or was lost"));
    s.push_back(duration(
        "groundlink.reconnect_max", [](Config& c) -> milliseconds& { return c.groundlink.reconnect_max; },
        milliseconds(10), hours(1), "longest retry delay for the radio ports"));
    s.push_back(string(
        "groundlink.udp.bind", [](Config& c) -> std::string& { return c.groundlink.udp_bind; },
        "local address of the UDP ground link (mode udp)", false));
    s.push_back(integer(
        "groundlink.udp.port", [](Config& c) -> int& { return c.groundlink.udp_port; }, 1, 65535,
        "local UDP port of the ground link"));
    s.push_back(string(
        "groundlink.udp.remote", [](Config& c) -> std::string& { return c.groundlink.udp_remote; },
        "fixed ground station address; empty = answer whoever sent last", true));
    s.push_back(integer(
        "groundlink.udp.remote_port", [](Config& c) -> int& { return c.groundlink.udp_remote_port; }, 0,
        65535, "UDP port of the fixed ground station (with udp.remote)"));
    s.push_back(string(
        "groundlink.monitor_key_file",
        [](Config& c) -> std::string& { return c.groundlink.monitor_key_file; },
        "second key file (mode 0600): its holders may watch but not command; empty = none", true));
    s.push_back(number_map(
        "groundlink.telemetry.rates",
        [](Config& c) -> std::map<std::string, double>& { return c.groundlink.telemetry_rates; },
        {"vehicle", "link_stats"}, false, "pushed telemetry per kind, Hz 0..20 (0 = off)", true));
    s.push_back(number(
        "groundlink.telemetry.budget_share",
        [](Config& c) -> double& { return c.groundlink.telemetry_budget_share; }, 0.01, 1.0,
        "fraction of the radio link rate pushed telemetry may use", true));
    s.push_back(number(
        "groundlink.telemetry.min_hz", [](Config& c) -> double& { return c.groundlink.telemetry_min_hz; },
        0.01, 20.0, "lowest rate of a telemetry kind that is on, however weak the link", true));
    s.push_back(boolean(
        "groundlink.mavlink_forward.enabled",
        [](Config& c) -> bool& { return c.groundlink.mavlink_forward_enabled; },
        "forward the autopilot's MAVLink over the ground link for standard ground stations (and theirs back, "
        "control key only)"));
    s.push_back(number(
        "groundlink.mavlink_forward.budget_bytes_per_s",
        [](Config& c) -> double& { return c.groundlink.mavlink_forward_budget; }, 0, 1e6,
        "bytes per second forwarded MAVLink may use; 0 = 30 % of the radio link rate"));
    s.push_back(number_map(
        "groundlink.mavlink_forward.rates",
        [](Config& c) -> std::map<std::string, double>& { return c.groundlink.mavlink_forward_rates; }, {},
        false,
        "Hz 0..50 per telemetry message forwarded (MAVLink name or id; 'default' for the others, 1 Hz); 0 = "
        "not forwarded"));
    // The radios' air. The bounds are RadioProfile::validate()'s, so that each bad key is reported at once;
    // validate() (run by the loader) adds the gaps (packet 1..7, buffer 1..63) and packet_overhead without
    // packet.
    s.push_back(integer(
        "groundlink.radio.air_speed",
        [](Config& c) -> std::uint32_t& { return c.groundlink.radio.air_speed_kbps; }, 0, 100'000,
        "kbit/s the radios send on air (SiK AIR_SPEED); 0 = the serial rate (baud / 10 bytes/s)"));
    s.push_back(boolean(
        "groundlink.radio.ecc", [](Config& c) -> bool& { return c.groundlink.radio.ecc; },
        "the radios send every byte with error correction (SiK ECC), which halves the air rate"));
    s.push_back(integer(
        "groundlink.radio.packet", [](Config& c) -> std::size_t& { return c.groundlink.radio.packet_bytes; },
        0, 4096, "payload bytes per air packet (SiK: 252); 0 = the air is a byte stream"));
    s.push_back(integer(
        "groundlink.radio.packet_overhead",
        [](Config& c) -> std::size_t& { return c.groundlink.radio.packet_overhead; }, 0, 256,
        "air bytes each packet adds (preamble, sync word, header, CRC); needs packet"));
    s.push_back(duration(
        "groundlink.radio.turnaround", [](Config& c) -> Duration& { return c.groundlink.radio.turnaround; },
        milliseconds(0), milliseconds(100), "air lost each time a half-duplex radio pair changes sender"));
    s.push_back(two_words(
        "groundlink.radio.duplex", [](Config& c) -> bool& { return c.groundlink.radio.half_duplex; }, "half",
        "full", "half: the two radios of a pair share their air time; full: each direction has its own"));
    s.push_back(integer(
        "groundlink.radio.buffer", [](Config& c) -> std::size_t& { return c.groundlink.radio.buffer_bytes; },
        0, 1 << 24, "bytes the radio holds before they go on air; 0 = unknown"));
    s.push_back(boolean(
        "groundlink.radio.adapt", [](Config& c) -> bool& { return c.groundlink.radio.adapt; },
        "pace to the air as measured from the link's own traffic (between a quarter of the rate the keys "
        "above give and that rate), not only as configured; the measurement is in status either way"));
    // Flight plans
    s.push_back(integer(
        "flightplan.window", [](Config& c) -> int& { return c.flightplan.window; }, 3, 250,
        "plan waypoints kept on the autopilot at a time (its mission must hold window + 2 items)"));
    s.push_back(choice(
        "flightplan.vehicle", [](Config& c) -> std::string& { return c.flightplan.vehicle; },
        {"rover", "boat", "copter", "plane"},
        "vehicle profile (min spacing, arrival radius, cruise speed) of plans that do not name one"));
    s.push_back(duration(
        "flightplan.request_timeout", [](Config& c) -> milliseconds& { return c.flightplan.request_timeout; },
        milliseconds(100), seconds(120), "wait for the autopilot to confirm one window request"));
    s.push_back(integer(
        "flightplan.retries", [](Config& c) -> int& { return c.flightplan.retries; }, 0, 100,
        "extra attempts of a window request before the vehicle is held"));
    s.push_back(boolean(
        "flightplan.resume_after_reboot", [](Config& c) -> bool& { return c.flightplan.resume_after_reboot; },
        "after an autopilot reboot, rebuild the window and drive on (false: stay paused)"));
    s.push_back(boolean(
        "flightplan.fsync", [](Config& c) -> bool& { return c.flightplan.fsync; },
        "fsync plan and progress files (false: they survive a daemon kill but not a power cut)"));
    s.push_back(duration(
        "flightplan.command_timeout", [](Config& c) -> milliseconds& { return c.flightplan.command_timeout; },
        milliseconds(100), hours(1), "how long a plan command waits for the autopilot's confirmation"));
    return s;
}

}  // namespace

const std::vector<KeySpec>& config_schema() {
    static const std::vector<KeySpec> schema = build_schema();
    return schema;
}

const KeySpec* find_key(const std::string& path) {
    for (const auto& spec : config_schema()) {
        if (spec.path == path) {
            return &spec;
        }
    }
    return nullptr;
}

bool is_section(const std::string& path) {
    const std::string prefix = path + ".";
    return std::any_of(config_schema().begin(), config_schema().end(),
                       [&](const KeySpec& spec) { return spec.path.starts_with(prefix); });
}

}  // namespace airseg::daemon
