// The ground hub's client framing and key proof: byte-exact, robust to any split of the stream, and strict
// about what cannot be framed.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "groundside/hub_wire.hpp"

namespace airseg::groundside::hub {
namespace {

std::vector<std::uint8_t> bytes_of(const std::string& s) {
    return {s.begin(), s.end()};
}

TEST(HubWire, FrameLayoutIsLengthTypePayload) {
    const auto frame = encode(FrameType::Ground, bytes_of("ab"));
    EXPECT_EQ(frame, (std::vector<std::uint8_t>{3, 0, 0, 0, 2, 'a', 'b'}));
}

TEST(HubWire, FramesSurviveEverySplitOfTheStream) {
    std::vector<std::uint8_t> stream = encode_json({{"hello", {{"want", "control"}}}});
    const auto second = encode(FrameType::Ground, bytes_of("xyz"));
    stream.insert(stream.end(), second.begin(), second.end());
    for (std::size_t cut = 0; cut <= stream.size(); ++cut) {
        FrameReader reader;
        ASSERT_TRUE(reader.push(std::span(stream).first(cut)));
        ASSERT_TRUE(reader.push(std::span(stream).subspan(cut)));
        auto a = reader.next();
        auto b = reader.next();
        ASSERT_TRUE(a && b) << "cut at " << cut;
        EXPECT_EQ(a->type, FrameType::Json);
        EXPECT_EQ(nlohmann::json::parse(a->payload)["hello"]["want"], "control");
        EXPECT_EQ(b->type, FrameType::Ground);
        EXPECT_EQ(b->payload, bytes_of("xyz"));
        EXPECT_FALSE(reader.next());
    }
}

TEST(HubWire, AnOversizedOrEmptyLengthBreaksTheStreamWithAReason) {
    FrameReader big;
    EXPECT_FALSE(big.push(std::vector<std::uint8_t>{0xff, 0xff, 0xff, 0x7f}));
    EXPECT_NE(big.error().find("bad frame length"), std::string::npos) << big.error();
    EXPECT_FALSE(big.push(encode(FrameType::Json, bytes_of("{}")))) << "nothing is framed after a bad length";

    FrameReader empty;
    EXPECT_FALSE(empty.push(std::vector<std::uint8_t>{0, 0, 0, 0}));
}

TEST(HubWire, AnUnknownFrameTypeIsRefused) {
    FrameReader reader;
    EXPECT_FALSE(reader.push(std::vector<std::uint8_t>{1, 0, 0, 0, 9}));
    EXPECT_NE(reader.error().find("unknown frame type 9"), std::string::npos) << reader.error();
}

TEST(HubWire, TheProofDependsOnKeyAndChallenge) {
    std::array<std::uint8_t, 32> key{};
    key.fill(0xcc);
    std::array<std::uint8_t, kChallengeBytes> challenge{};
    challenge.fill(1);
    const auto p = proof(key, challenge);
    EXPECT_EQ(p, proof(key, challenge));
    challenge[0] = 2;
    EXPECT_NE(p, proof(key, challenge));
    challenge[0] = 1;
    key[31] = 0;
    EXPECT_NE(p, proof(key, challenge));
}

TEST(HubWire, HexRoundTripsAndRejectsWhatIsNotHex) {
    const std::vector<std::uint8_t> b{0x00, 0x7f, 0xff};
    EXPECT_EQ(to_hex(b), "007fff");
    EXPECT_EQ(from_hex("007fff"), b);
    EXPECT_EQ(from_hex("007FFF"), b);
    EXPECT_FALSE(from_hex("07f"));
    EXPECT_FALSE(from_hex("zz"));
    EXPECT_FALSE(from_hex("00 1"));
}

}  // namespace
}  // namespace airseg::groundside::hub
