#pragma once
// A realistic autopilot telemetry stream for the benchmarks: what ArduPilot Rover sends on a telemetry port
// with the usual stream rates (attitude 10 Hz, position/GPS/HUD 5 Hz, status and RC 2 Hz, heartbeat and the
// rest 1 Hz, an occasional STATUSTEXT), MAVLink 2, values that move as a driving vehicle's do. Seeded.
#include <cstdint>
#include <vector>

namespace airseg::mavlink::bench {

struct TelemetryStream {
    std::vector<std::uint8_t> bytes;
    std::size_t frames = 0;
};

TelemetryStream make_telemetry_stream(double seconds, unsigned seed = 1);

}  // namespace airseg::mavlink::bench
