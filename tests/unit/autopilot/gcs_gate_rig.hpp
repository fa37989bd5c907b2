#pragma once
// The gate's test rig, shared by its two test files: a gate for board 1/1, a ground station's encoder in
// front of it, and a parser for what comes out.
#include <cstdint>
#include <span>
#include <vector>

#include "services/autopilot/gcs_gate.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::autopilot::gate_test {

/// Every frame in `bytes`, in order.
inline std::vector<mavlink::Frame> parse(std::span<const std::uint8_t> bytes) {
    std::vector<mavlink::Frame> out;
    mavlink::Parser p;
    p.push(bytes, [&](const mavlink::Frame& f) { out.push_back(f); });
    p.finish([&](const mavlink::Frame& f) { out.push_back(f); });
    return out;
}

struct Rig {
    GcsGate gate{1, 1};
    mavlink::Encoder gcs{254, 190};
};

}  // namespace airseg::autopilot::gate_test
