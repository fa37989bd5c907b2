// Telemetry bytes per sample on the wire, transport framing included, measured on a keyed link between two
// transport cores in simulated time: every frame the vehicle end writes is handed to the ground end, and a
// frame after which the ground end delivers a telemetry sample is that sample's cost on the air.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <random>

#include "services/groundlink/protocol/ground_protocol.hpp"
#include "services/groundlink/telemetry_sample.hpp"
#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundlink {
namespace {

TransportConfig keyed(std::uint64_t nonce) {
    TransportConfig c;
    c.key = std::array<std::uint8_t, kKeyBytes>{};
    for (std::size_t i = 0; i < kKeyBytes; ++i) {
        (*c.key)[i] = static_cast<std::uint8_t>(i * 7 + 1);
    }
    c.boot_nonce = nonce;
    return c;
}

TEST(TelemetrySample, TheModeTravelsAsTheAutopilotsNumber) {
    autopilot::Telemetry t;
    EXPECT_EQ(make_sample(t).mode, protocol::kModeUnknown) << "no mode yet";
    t.mode = "AUTO";
    t.custom_mode = 10;
    EXPECT_EQ(make_sample(t).mode, 10);
    t.mode = "MODE(9)";
    t.custom_mode = 9;
    EXPECT_EQ(make_sample(t).mode, 9) << "a number without a name still travels";
    t.mode = "MODE(254)";
    t.custom_mode = 254;
    EXPECT_EQ(make_sample(t).mode, 254);
    t.mode = "MODE(999)";
    t.custom_mode = 999;
    EXPECT_EQ(make_sample(t).mode, protocol::kModeUnknown) << "too large for the byte";
}

TEST(TelemetrySample, WithoutAValidPositionTheSampleSaysSoAndCarriesNoPlace) {
    autopilot::Telemetry t;
    t.gps_fix = autopilot::GpsFix::Fix3D;
    t.position_invalid = "latitude 199.1700000 outside ±90";
    auto s = make_sample(t);
    EXPECT_TRUE(s.no_position);
    EXPECT_EQ(s.lat_deg, 0.0);
    EXPECT_EQ(s.lon_deg, 0.0);
    const auto decoded = protocol::decode(protocol::encode(s));
    ASSERT_TRUE(decoded.message) << decoded.error;
    EXPECT_TRUE(std::get<protocol::Telemetry>(*decoded.message).no_position);

    t.position = autopilot::Position{41.2756, 1.9866, 12.0};
    t.position_invalid.clear();
    s = make_sample(t);
    EXPECT_FALSE(s.no_position);
    EXPECT_DOUBLE_EQ(s.lat_deg, 41.2756);
}

TEST(TelemetryOnTheWire, ASampleCostsAtMostFortyEightBytesIncludingFraming) {
    TimePoint now = TimePoint{} + std::chrono::hours(1);
    Transport vehicle(keyed(0x1111), now), ground(keyed(0x2222), now);
    std::mt19937 rng(42);
    std::vector<std::size_t> sample_frames;
    std::size_t delivered = 0;
    TimePoint next_sample = now + std::chrono::seconds(2);  // after the handshake
    const TimePoint end = now + std::chrono::seconds(62);
    while (now < end) {
        if (now >= next_sample && vehicle.link_up()) {
            autopilot::Telemetry t;
            t.position = autopilot::Position{41.27 + (rng() % 100000) * 1e-7, 1.98 + (rng() % 100000) * 1e-7,
                                             12.0 + (rng() % 100) * 0.1};
            t.ground_speed = (rng() % 300) / 100.0;
            t.heading = (rng() % 36000) / 100.0;
            t.battery_voltage = 12.0 + (rng() % 100) / 100.0;
            t.battery_remaining = static_cast<int>(rng() % 101);
            t.gps_fix = autopilot::GpsFix::Fix3D;
            t.satellites = 9;
            t.mode = "AUTO";
            t.custom_mode = 10;
            t.state = autopilot::VehicleState::WaypointNavigation;
            vehicle.send_fast(protocol::kPriorityTelemetry, protocol::kTopicTelemetry,
                              protocol::encode(make_sample(t)), now);
            next_sample += std::chrono::milliseconds(500);
        }
        while (auto frame = vehicle.poll_transmit(0, now)) {
            ground.handle_bytes(0, *frame, now);
            while (auto m = ground.poll_message()) {
                auto d = protocol::decode(m->bytes);
                if (d.message && std::holds_alternative<protocol::Telemetry>(*d.message)) {
                    sample_frames.push_back(frame->size());
                    ++delivered;
                }
            }
        }
        while (auto frame = ground.poll_transmit(0, now)) {
            vehicle.handle_bytes(0, *frame, now);
        }
        while (vehicle.poll_message() || vehicle.poll_event() || ground.poll_event()) {
        }
        now += std::chrono::milliseconds(1);
        if (vehicle.poll_timeout() <= now) {
            vehicle.handle_timeout(now);
        }
        if (ground.poll_timeout() <= now) {
            ground.handle_timeout(now);
        }
    }
    ASSERT_GE(delivered, 115u) << "2 Hz for 60 s";
    const auto max = *std::max_element(sample_frames.begin(), sample_frames.end());
    double mean = 0;
    for (auto n : sample_frames) {
        mean += static_cast<double>(n);
    }
    mean /= static_cast<double>(sample_frames.size());
    std::cout << "telemetry on the wire: " << sample_frames.size() << " samples, mean " << mean << " B, max "
              << max << " B per sample (29 B message + framing, keyed link)\n";
    RecordProperty("bytes_per_sample_max", static_cast<int>(max));
    EXPECT_LE(max, 48u);
}

}  // namespace
}  // namespace airseg::groundlink
