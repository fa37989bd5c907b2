#include "services/groundlink/transport/radio_profile.hpp"

#include <charconv>
#include <cmath>
#include <string>

namespace airseg::groundlink {
namespace {

constexpr std::uint32_t kMaxAirSpeedKbps = 100'000;
constexpr std::size_t kMaxBuffer = std::size_t{1} << 24;

template <typename T>
bool parse_unsigned(std::string_view text, T& out) {
    T value{};
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc{} || end != text.data() + text.size()) {
        return false;
    }
    out = value;
    return true;
}

/// "10ms", "10" (milliseconds) or "0.5ms".
bool parse_milliseconds(std::string_view text, Duration& out) {
    if (text.ends_with("ms")) {
        text.remove_suffix(2);
    }
    double ms = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), ms);
    if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(ms) || ms < 0.0) {
        return false;
    }
    out = std::chrono::duration_cast<Duration>(std::chrono::duration<double, std::milli>(ms));
    return true;
}

bool parse_switch(std::string_view text, bool& out) {
    if (text == "on" || text == "true" || text == "1") {
        out = true;
    } else if (text == "off" || text == "false" || text == "0") {
        out = false;
    } else {
        return false;
    }
    return true;
}

std::string key_error(std::string_view key, std::string_view value, std::string_view expected) {
    return "--radio " + std::string(key) + "=" + std::string(value) + ": " + std::string(expected);
}

}  // namespace

std::string RadioProfile::validate(std::string_view prefix) const {
    // A YAML key reads groundlink.radio.packet, an option's value --radio packet.
    const std::string p = std::string(prefix) + (prefix.starts_with("--") ? " " : ".");
    if (air_speed_kbps > kMaxAirSpeedKbps) {
        return p + "air_speed must be 0 (the serial rate) or 1..100000 kbit/s";
    }
    if (packet_bytes != 0 && (packet_bytes < 8 || packet_bytes > 4096)) {
        return p + "packet must be 0 (no packets) or 8..4096 bytes";
    }
    if (packet_overhead > 256) {
        return p + "packet_overhead must be 0..256 bytes";
    }
    if (packet_bytes == 0 && packet_overhead != 0) {
        return p + "packet_overhead needs packet (the bytes each packet carries)";
    }
    if (turnaround < Duration::zero() || turnaround > std::chrono::milliseconds(100)) {
        return p + "turnaround must be 0..100 ms";
    }
    if (buffer_bytes != 0 && (buffer_bytes < 64 || buffer_bytes > kMaxBuffer)) {
        return p + "buffer must be 0 (unknown) or 64..16777216 bytes";
    }
    return {};
}

double RadioProfile::air_bytes_per_s(double serial_bytes_per_s) const {
    const double raw = air_speed_kbps != 0 ? air_speed_kbps * 1000.0 / 8.0 : serial_bytes_per_s;
    return ecc ? raw / 2.0 : raw;
}

void RadioProfile::apply(TransportConfig& config, double serial_bytes_per_s) const {
    const double air = air_bytes_per_s(serial_bytes_per_s);
    // Equal to the serial rate means nothing more to pace for.
    config.air_rate_bytes_per_s = air == serial_bytes_per_s ? 0.0 : air;
    config.air_packet_payload = packet_bytes;
    config.air_packet_overhead = packet_overhead;
    config.air_turnaround = turnaround;
    config.half_duplex = half_duplex;
    config.radio_buffer_bytes = buffer_bytes;
    config.air_adapt = adapt;
}

std::string parse_radio_profile(std::string_view text, RadioProfile& profile) {
    RadioProfile p = profile;
    while (!text.empty()) {
        const auto comma = text.find(',');
        const std::string_view item = text.substr(0, comma);
        text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
        if (item.empty()) {
            continue;
        }
        const auto eq = item.find('=');
        if (eq == std::string_view::npos) {
            return "--radio " + std::string(item) + ": expected KEY=VALUE";
        }
        const std::string_view key = item.substr(0, eq);
        const std::string_view value = item.substr(eq + 1);
        bool ok = true;
        if (key == "air_speed") {
            ok = parse_unsigned(value, p.air_speed_kbps);
        } else if (key == "ecc") {
            ok = parse_switch(value, p.ecc);
        } else if (key == "packet") {
            ok = parse_unsigned(value, p.packet_bytes);
        } else if (key == "packet_overhead") {
            ok = parse_unsigned(value, p.packet_overhead);
        } else if (key == "turnaround") {
            ok = parse_milliseconds(value, p.turnaround);
        } else if (key == "duplex") {
            ok = value == "half" || value == "full";
            p.half_duplex = value != "full";
        } else if (key == "buffer") {
            ok = parse_unsigned(value, p.buffer_bytes);
        } else if (key == "adapt") {
            ok = parse_switch(value, p.adapt);
        } else {
            return "--radio " + std::string(key) +
                   ": unknown key (air_speed, ecc, packet, packet_overhead, turnaround, duplex, buffer, "
                   "adapt)";
        }
        if (!ok) {
            const char* expected = key == "ecc" || key == "adapt" ? "expected on or off"
                                   : key == "duplex"              ? "expected half or full"
                                   : key == "turnaround"          ? "expected milliseconds, e.g. 10ms"
                                                                  : "expected a whole number";
            return key_error(key, value, expected);
        }
    }
    if (auto error = p.validate("--radio"); !error.empty()) {
        return error;
    }
    profile = p;
    return {};
}

}  // namespace airseg::groundlink
