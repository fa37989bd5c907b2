// RoverSim against hostile input: random bytes and well-framed messages with random payloads, from several
// senders, in every boot phase. It must neither crash nor stop being a board (heartbeats, answers).
#include <gtest/gtest.h>

#include <random>

#include "services/autopilot/mavlink/message_table.hpp"
#include "tests/integration/apmsim/sim_harness.hpp"

namespace airseg::apmsim::test {
namespace {

std::vector<std::uint8_t> random_frame(std::mt19937_64& rng) {
    const auto messages = mv::all_messages();
    const mv::MessageInfo& info = messages[rng() % messages.size()];
    std::array<std::uint8_t, mv::kMaxPayload> payload{};
    for (std::size_t i = 0; i < info.length; ++i) {
        payload[i] = static_cast<std::uint8_t>(rng());
    }
    // Aim most frames at us, so the handlers see them.
    if (rng() % 4 != 0 && info.length >= 2) {
        for (const auto& field : info.fields) {
            if (field.name == "target_system") {
                payload[field.offset] = 1;
            }
        }
    }
    mv::FrameHeader header;
    header.version = rng() % 3 == 0 ? mv::Version::V1 : mv::Version::V2;
    header.sysid = static_cast<std::uint8_t>(250 + rng() % 6);
    header.compid = static_cast<std::uint8_t>(rng());
    header.msgid = info.id;
    std::array<std::uint8_t, mv::kMaxFrameLength> out{};
    const std::size_t n = mv::encode_message(header, info, std::span(payload).first(info.length), out);
    return std::vector<std::uint8_t>(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
}

TEST(ApmsimRobustness, RandomFramesAndNoise) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
        std::mt19937_64 rng(seed);
        SimHarness h;
        for (int i = 0; i < 4000; ++i) {
            std::vector<std::uint8_t> bytes;
            if (rng() % 5 == 0) {
                bytes.resize(rng() % 64);
                for (auto& b : bytes) {
                    b = static_cast<std::uint8_t>(rng());
                }
            } else {
                bytes = random_frame(rng);
            }
            h.sim.handle_bytes(bytes, h.now);
            h.run_for(milliseconds(static_cast<int>(rng() % 50)));
        }
        // Whatever it went through, it is still a board: it boots and answers.
        h.sim.faults() = Faults{};
        h.sim.reboot(h.now);
        h.boot();
        const std::size_t from = h.received.size();
        h.send(mv::MissionRequestList{});
        h.run_for(seconds(2));
        EXPECT_TRUE(h.last<mv::MissionCount>(from)) << "seed " << seed;
        EXPECT_TRUE(h.last<mv::Heartbeat>(from)) << "seed " << seed;
        EXPECT_LE(h.sim.mission().count(), h.sim.mission().capacity());
    }
}

}  // namespace
}  // namespace airseg::apmsim::test
