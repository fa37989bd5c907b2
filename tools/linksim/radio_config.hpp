#pragma once
// Configuration of the simulated radio pair: the serial lines on both ends, the shared air, and the
// impairments of each direction. Plain data with a validate() that needs no hardware.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "base/time.hpp"

namespace airseg::linksim {

/// The two radios of a pair. A direction is named by its sending side: impairment[A] applies to bytes A→B.
enum class Side : std::uint8_t { A = 0, B = 1 };

constexpr Side other(Side s) {
    return s == Side::A ? Side::B : Side::A;
}
constexpr std::size_t index(Side s) {
    return static_cast<std::size_t>(s);
}
const char* to_string(Side s);

/// Half: both directions share one air channel (SiK, XBee, XTend as measured in the field).
/// Full: each direction has its own channel (two frequencies, or a wire).
enum class Duplex : std::uint8_t { Half, Full };

/// A radio blackout, as an offset from the model's start time.
struct Outage {
    Duration start{0};
    Duration length{0};
};

/// What happens to bytes travelling in one direction.
struct DirectionImpairment {
    double byte_loss = 0.0;        ///< probability that one byte vanishes on the air
    double byte_corruption = 0.0;  ///< probability that one byte arrives with one random bit flipped
    double bit_error_rate = 0.0;   ///< probability that one bit is flipped (applied per byte)
    double frame_loss = 0.0;       ///< probability that a whole air packet is lost
    Duration latency{0};           ///< added between the end of an air packet and its delivery
    std::vector<Outage> outages;   ///< air packets overlapping an outage are lost
};

struct RadioConfig {
    std::uint32_t baud = 57600;      ///< serial line between each host and its radio, 8N1 (baud/10 bytes/s)
    std::uint32_t air_rate_bps = 0;  ///< raw air bit rate (bytes/s = bps/8); 0 = the serial byte rate
    Duplex duplex = Duplex::Half;
    Duration turnaround = std::chrono::microseconds(1000);  ///< half duplex: dead air when the sender changes
    std::size_t max_air_packet = 252;                       ///< payload bytes per air packet (SiK: 252)
    std::size_t air_packet_overhead = 0;  ///< preamble/sync/header bytes sent on air with each packet
    std::size_t radio_buffer = 2048;  ///< each radio's serial-side FIFO; bytes arriving when full are dropped
    std::size_t host_buffer = 4096;   ///< each host's UART transmit buffer (the kernel's tty buffer)
    std::array<DirectionImpairment, 2> impairment{};  ///< indexed by the sending side
    /// A USB serial adapter between a receiving radio and its host (FTDI class), indexed by the host's side:
    /// the adapter sends the bytes it holds when it has usb_packet of them or when its latency timer, which
    /// restarts at every packet, expires. 0 = no adapter: each byte reaches the host as it leaves the UART.
    std::array<Duration, 2> usb_latency{};
    std::size_t usb_packet = 62;  ///< data bytes per USB packet (FTDI full speed: 64 minus 2 status bytes)
    std::uint64_t seed = 1;

    /// Empty when usable, otherwise a message naming the first bad field.
    std::string validate() const;

    double serial_bytes_per_second() const { return baud / 10.0; }
    double air_bytes_per_second() const { return air_rate_bps != 0 ? air_rate_bps / 8.0 : baud / 10.0; }
};

}  // namespace airseg::linksim
