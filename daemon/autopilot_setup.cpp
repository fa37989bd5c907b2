#include "daemon/autopilot_setup.hpp"

#include <algorithm>
#include <map>

namespace airseg::daemon {
namespace {

using autopilot::DataStream;

const std::map<std::string, DataStream>& stream_names() {
    static const std::map<std::string, DataStream> names{
        {"raw_sensors", DataStream::RawSensors}, {"extended_status", DataStream::ExtendedStatus},
        {"rc_channels", DataStream::RcChannels}, {"position", DataStream::Position},
        {"extra1", DataStream::Extra1},          {"extra2", DataStream::Extra2},
        {"extra3", DataStream::Extra3}};
    return names;
}

/// "gpiochip0:17" names a chip and an offset; anything else is a line name from the device tree.
hal::GpioLineRequest gpio_line(const std::string& text) {
    hal::GpioLineRequest r;
    r.direction = hal::GpioDirection::Output;
    r.initial_value = false;
    const auto colon = text.rfind(':');
    const std::string offset = colon == std::string::npos ? "" : text.substr(colon + 1);
    if (colon != std::string::npos && colon > 0 && !offset.empty() && offset.size() <= 6 &&
        offset.find_first_not_of("0123456789") == std::string::npos) {
        r.chip = text.substr(0, colon);
        r.offset = static_cast<unsigned>(std::stoul(offset));
    } else {
        r.line_name = text;
    }
    return r;
}

}  // namespace

AutopilotSetup autopilot_setup(const Config& config) {
    const auto& a = config.autopilot;
    AutopilotSetup out;
    auto& s = out.service;
    auto& ap = s.autopilot;
    ap = autopilot::AutopilotConfig::defaults_for(a.board == "pixhawk" ? autopilot::Board::Pixhawk
                                                                       : autopilot::Board::Apm2);
    ap.bauds.clear();
    for (int b : a.bauds.empty() ? std::vector<int>{a.baud} : a.bauds) {
        ap.bauds.push_back(static_cast<unsigned>(b));
    }
    ap.baud_probe = a.baud_probe;
    if (a.reset_on_open != "auto") {
        ap.reset_on_open = a.reset_on_open == "true";
    }
    ap.gcs_heartbeat = a.gcs_heartbeat != "off";
    ap.gcs_heartbeat_type =
        a.gcs_heartbeat == "onboard" ? autopilot::kMavTypeOnboardController : autopilot::kMavTypeGcs;
    ap.boot_timeout = a.boot_timeout;
    ap.heartbeat_timeout = a.heartbeat_timeout;
    ap.mode_timeout = a.mode_timeout;
    ap.arming = a.arming == "never" ? autopilot::ArmingPolicy::Never : autopilot::ArmingPolicy::Auto;
    for (const auto& [name, value] : a.params) {
        ap.params.push_back({name, value});
    }
    if (!a.streams.empty()) {
        ap.stream_rates.clear();
        for (const auto& [name, hz] : a.streams) {
            // The schema admits only known names and whole numbers >= 0; validate() checks the upper bound.
            ap.stream_rates.push_back({stream_names().at(name), static_cast<unsigned>(std::min(hz, 1e6))});
        }
    }
    std::vector<std::string> unknown_messages;
    if (!a.message_rates.empty()) {
        ap.message_rates.clear();
        for (const auto& [name, hz] : a.message_rates) {
            if (const auto id = autopilot::message_id(name)) {
                ap.message_rates.push_back({*id, hz});
            } else {
                unknown_messages.push_back("autopilot.message_rates: " + name +
                                           " is not a MAVLink message this daemon knows");
            }
        }
    }
    ap.rc_override.rate_hz = a.rc_override_rate_hz;
    ap.rc_override.input_timeout = a.rc_override_input_timeout;
    ap.unresponsive_timeout = a.reset_unresponsive_timeout;
    ap.max_reset_pulses = static_cast<unsigned>(a.reset_max_pulses);

    s.port.serial.path = a.port;
    s.port.serial.baud = ap.bauds.empty() ? 115200u : ap.bauds.front();
    s.port.reconnect_min = a.reconnect_min;
    s.port.reconnect_max = a.reconnect_max;

    s.tlog.enabled = a.tlog_enabled;
    s.tlog.path = a.tlog_path;
    s.tlog.max_bytes = static_cast<std::uint64_t>(a.tlog_max_bytes);
    s.tlog.keep = static_cast<unsigned>(a.tlog_keep);
    s.forward_frames = config.groundlink.mavlink_forward_enabled;
    if (!a.gcs_endpoint_udp.empty() || !a.gcs_endpoint_tcp.empty()) {
        s.gcs_endpoint = autopilot::GcsEndpointConfig{a.gcs_endpoint_udp, a.gcs_endpoint_tcp, ""};
        for (const auto& p : s.gcs_endpoint->validate()) {
            out.problems.push_back("autopilot.gcs_endpoint." + p);  // "udp: ..." names the key's last part
        }
    }

    out.problems = autopilot::AutopilotConfig::validate(ap);
    out.problems.insert(out.problems.end(), unknown_messages.begin(), unknown_messages.end());
    for (auto& p : autopilot::TlogConfig::validate(s.tlog)) {
        out.problems.push_back(std::move(p));
    }
    if (!a.reset_line.empty()) {
        s.reset_line = gpio_line(a.reset_line);
        for (auto& p : hal::GpioLineRequest::validate(*s.reset_line)) {
            out.problems.push_back("autopilot.reset.line: " + p);
        }
    }
    if (!config.status_led.line.empty()) {
        out.status_led = gpio_line(config.status_led.line);
        out.status_led->active_low = config.status_led.active_low;
        out.status_led->consumer = "airsegd status led";
        for (auto& p : hal::GpioLineRequest::validate(*out.status_led)) {
            out.problems.push_back("status_led.line: " + p);
        }
    }
    return out;
}

ForwardSetup mavlink_forward_setup(const Config& config) {
    const auto& g = config.groundlink;
    ForwardSetup out;
    out.config.enabled = g.mavlink_forward_enabled;
    out.config.budget_bytes_per_s = g.mavlink_forward_budget;
    constexpr std::uint32_t kMaxId = 0xFFFFFF;
    for (const auto& [key, hz] : g.mavlink_forward_rates) {
        if (key == "default") {
            out.config.default_hz = hz;
            continue;
        }
        std::optional<std::uint32_t> id = autopilot::message_id(key);
        if (!id && !key.empty() && key.size() <= 8 &&
            std::all_of(key.begin(), key.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) {
            if (const auto n = std::stoul(key); n <= kMaxId) {
                id = static_cast<std::uint32_t>(n);
            }
        }
        if (!id) {
            out.problems.push_back("groundlink.mavlink_forward.rates: " + key +
                                   " is neither a MAVLink message this daemon knows nor a message id");
            continue;
        }
        out.config.rate_hz[*id] = hz;
    }
    for (auto& p : out.config.validate()) {
        out.problems.push_back(std::move(p));
    }
    return out;
}

std::string problem_key(const std::string& problem) {
    const auto colon = problem.find(": ");
    if (colon == std::string::npos ||
        !(problem.starts_with("autopilot.") || problem.starts_with("status_led."))) {
        return {};
    }
    const std::string key = problem.substr(0, colon);
    return key.find_first_of(" /") == std::string::npos ? key : std::string{};
}

}  // namespace airseg::daemon
