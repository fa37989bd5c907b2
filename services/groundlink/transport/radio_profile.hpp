#pragma once
// What the radios do on air, in the units their own configuration uses (a SiK radio's AIR_SPEED in kbit/s,
// ECC on or off, its packet length), turned into the transport's pacing parameters. One description for
// both ends: airsegd reads it from groundlink.radio, airseg-ground and airsegctl from --radio.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "base/time.hpp"
#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundlink {

struct RadioProfile {
    /// air_speed: kbit/s on air (SiK AIR_SPEED); 0 = what the serial port carries (baud / 10 bytes/s).
    std::uint32_t air_speed_kbps = 0;
    /// ecc: the radios send every byte twice as long (SiK's 12/24 Golay code halves the air rate).
    bool ecc = false;
    /// packet: payload bytes per air packet (SiK: 252); 0 = the air is a byte stream.
    std::size_t packet_bytes = 252;
    /// packet_overhead: air bytes each packet adds (preamble, sync word, header, CRC).
    std::size_t packet_overhead = 0;
    /// turnaround: dead air when a half-duplex pair changes sender.
    Duration turnaround = std::chrono::milliseconds(1);
    bool half_duplex = true;
    /// buffer: bytes the radio holds before the air (0 = unknown).
    std::size_t buffer_bytes = 0;
    /// adapt: pace to the air as measured from the link's own traffic, between a quarter of what the keys
    /// above describe and that (TransportConfig::air_adapt).
    bool adapt = false;

    /// Empty when usable, else what is wrong, naming the key under `prefix` (groundlink.radio, --radio).
    std::string validate(std::string_view prefix) const;
    /// The air's payload rate in bytes/s for a serial port carrying serial_bytes_per_s.
    double air_bytes_per_s(double serial_bytes_per_s) const;
    /// Sets the transport's air parameters (link_rate stays what the serial port carries).
    void apply(TransportConfig& config, double serial_bytes_per_s) const;
};

/// Parses "air_speed=64,ecc=on,packet=252,packet_overhead=8,turnaround=10ms,duplex=half,buffer=2048,adapt=on"
/// (any subset, in any order) over `profile`. Empty when it parsed and validated, else the error, naming the
/// key.
std::string parse_radio_profile(std::string_view text, RadioProfile& profile);

}  // namespace airseg::groundlink
