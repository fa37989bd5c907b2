#pragma once
// A seeded, ArduPilot-like telemetry stream for parser tests, and a noisy line to send it over.
//
// The stream is what an ArduPilot vehicle sends on a telemetry port with its usual stream rates: the
// messages airseg declares (HEARTBEAT, SYS_STATUS, GPS_RAW_INT, ATTITUDE, GLOBAL_POSITION_INT, VFR_HUD,
// MISSION_CURRENT, RC_CHANNELS, SERVO_OUTPUT_RAW, STATUSTEXT, PARAM_VALUE bursts, mission downloads, ...)
// and as many it does not (AHRS, AHRS2, RAW_IMU, VIBRATION, EKF_STATUS_REPORT, ESC_TELEMETRY_1_TO_4, ...;
// their CRC_EXTRA and lengths as published for ardupilotmega.xml), MAVLink 2 with trailing-zero payload
// truncation, stretches where the autopilot talks MAVLink 1 (a ground station that asked for it), a SiK
// radio's RADIO_STATUS in MAVLink 1, and a few signed frames.
//
// The line corrupts each byte with a given probability: most often one flipped bit, sometimes the byte is
// lost or a random byte is inserted before it. Each sent frame records whether all its bytes arrived
// unchanged and in place (intact).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tests/unit/mavlink/reference_parser.hpp"

namespace airseg::mavlink::test {

using Bytes = std::vector<std::uint8_t>;

struct SentFrame {
    std::uint64_t key = 0;        // content_key() of the frame: header fields and payload as sent
    bool declared = false;        // its message id is in airseg's messages.def
    bool v2 = false;              // MAVLink 2 (else 1)
    bool is_signed = false;       // MAVLink 2 with a signature
    bool intact = false;          // every byte arrived unchanged, none lost or inserted inside it
    std::size_t received_at = 0;  // where its first byte arrived (for diagnostics)
};

struct NoisyStream {
    Bytes sent;      // the bytes the autopilot wrote
    Bytes received;  // the bytes after the line
    std::vector<SentFrame> frames;
    std::size_t flips = 0;
    std::size_t losses = 0;
    std::size_t insertions = 0;
};

struct LineNoise {
    double byte_error_rate = 1e-4;  // probability that a byte is corrupted in some way
    double loss_share = 0.1;        // of the corruptions: the byte is lost
    double insertion_share = 0.1;   // of the corruptions: a random byte arrives before it
};

/// At least `bytes` bytes of telemetry (whole frames), sent through `noise`. Deterministic for a seed.
NoisyStream make_ardupilot_stream(std::size_t bytes, std::uint32_t seed, const LineNoise& noise = {});

/// A hash of what a decoder delivers of a frame: version, flags, sequence, ids and the payload bytes as
/// carried on the wire (not the checksum or the signature).
std::uint64_t content_key(bool v2, std::uint8_t incompat_flags, std::uint8_t compat_flags, std::uint8_t seq,
                          std::uint8_t sysid, std::uint8_t compid, std::uint32_t msgid,
                          const std::uint8_t* payload, std::size_t payload_length);

/// The reference parser's message table for the messages airseg declares (from its message table).
std::vector<reference::MsgEntry> declared_entries();
/// The same, plus the undeclared ArduPilot messages the stream carries, with their published entries.
std::vector<reference::MsgEntry> ardupilot_entries();

}  // namespace airseg::mavlink::test
