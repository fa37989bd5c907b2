#include "tools/linksim/radio_config.hpp"

#include <string>

namespace airseg::linksim {

const char* to_string(Side s) {
    return s == Side::A ? "a" : "b";
}

namespace {

bool is_probability(double p) {
    return p >= 0.0 && p <= 1.0;
}

std::string check_direction(const DirectionImpairment& d, const char* name) {
    const std::string where = std::string("impairment ") + name + ": ";
    if (!is_probability(d.byte_loss)) {
        return where + "byte_loss must be within [0, 1]";
    }
    if (!is_probability(d.byte_corruption)) {
        return where + "byte_corruption must be within [0, 1]";
    }
    if (!is_probability(d.bit_error_rate)) {
        return where + "bit_error_rate must be within [0, 1]";
    }
    if (!is_probability(d.frame_loss)) {
        return where + "frame_loss must be within [0, 1]";
    }
    if (d.latency < Duration::zero()) {
        return where + "latency must not be negative";
    }
    for (std::size_t i = 0; i < d.outages.size(); ++i) {
        if (d.outages[i].start < Duration::zero() || d.outages[i].length <= Duration::zero()) {
            return where + "outage " + std::to_string(i + 1) + " needs start >= 0 and a positive duration";
        }
    }
    return {};
}

}  // namespace

std::string RadioConfig::validate() const {
    if (baud < 300 || baud > 4'000'000) {
        return "baud must be within [300, 4000000], got " + std::to_string(baud);
    }
    if (air_rate_bps != 0 && (air_rate_bps < 300 || air_rate_bps > 100'000'000)) {
        return "air_rate_bps must be 0 (serial rate) or within [300, 100000000], got " +
               std::to_string(air_rate_bps);
    }
    if (turnaround < Duration::zero()) {
        return "turnaround must not be negative";
    }
    if (max_air_packet == 0 || max_air_packet > 65536) {
        return "max_air_packet must be within [1, 65536]";
    }
    if (air_packet_overhead > 65536) {
        return "air_packet_overhead must be at most 65536";
    }
    if (radio_buffer == 0 || radio_buffer > (1U << 24)) {
        return "radio_buffer must be within [1, 16777216]";
    }
    if (host_buffer == 0 || host_buffer > (1U << 24)) {
        return "host_buffer must be within [1, 16777216]";
    }
    for (Side s : {Side::A, Side::B}) {
        const Duration l = usb_latency[index(s)];
        if (l < Duration::zero() || l > std::chrono::milliseconds(255)) {
            return std::string("usb_latency of host ") + to_string(s) +
                   " must be within [0, 255] ms (0: no adapter)";
        }
    }
    if (usb_packet == 0 || usb_packet > 65536) {
        return "usb_packet must be within [1, 65536]";
    }
    if (auto e = check_direction(impairment[0], "a->b"); !e.empty()) {
        return e;
    }
    return check_direction(impairment[1], "b->a");
}

}  // namespace airseg::linksim
