// The parser's frames and counters do not depend on how the stream is split into push() calls (the
// invariant tests/fuzz/mavlink/parser_fuzz.cpp checks under libFuzzer), here with GCC on what the fast
// paths meet: a long noisy ArduPilot stream (unknown ids, MAVLink 1 stretches, signed frames, lost and
// inserted bytes) read byte by byte, in UART-sized and in random-sized reads, and the fuzz seeds.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "services/autopilot/mavlink/parser.hpp"
#include "tests/support/tree_paths.hpp"
#include "tests/unit/mavlink/ardupilot_stream.hpp"

namespace airseg::mavlink {
namespace {

using test::Bytes;

struct SplitOutcome {
    std::vector<Frame> frames;
    ParserStats stats;
};

// Reads of the sizes `next_size()` returns, then finish().
template <class NextSize>
SplitOutcome run_split(const Bytes& bytes, NextSize next_size) {
    Parser parser;
    SplitOutcome out;
    auto sink = [&](const Frame& f) { out.frames.push_back(f); };
    for (std::size_t i = 0; i < bytes.size();) {
        const std::size_t n = std::min(next_size(), bytes.size() - i);
        parser.push(std::span(bytes).subspan(i, n), sink);
        i += n;
    }
    parser.finish(sink);
    out.stats = parser.stats();
    return out;
}

bool same_split_frame(const Frame& a, const Frame& b) {
    return a.version == b.version && a.incompat_flags == b.incompat_flags &&
           a.compat_flags == b.compat_flags && a.seq == b.seq && a.sysid == b.sysid && a.compid == b.compid &&
           a.msgid == b.msgid && a.wire_length == b.wire_length && a.payload_length == b.payload_length &&
           a.is_signed == b.is_signed && a.checksum_verified == b.checksum_verified && a.payload == b.payload;
}

void expect_same(const SplitOutcome& whole, const SplitOutcome& split, const char* how) {
    ASSERT_EQ(whole.frames.size(), split.frames.size()) << how;
    for (std::size_t i = 0; i < whole.frames.size(); ++i) {
        ASSERT_TRUE(same_split_frame(whole.frames[i], split.frames[i])) << how << ", frame " << i;
    }
    EXPECT_EQ(whole.stats.frames_ok, split.stats.frames_ok) << how;
    EXPECT_EQ(whole.stats.garbage_bytes, split.stats.garbage_bytes) << how;
    EXPECT_EQ(whole.stats.bad_checksum, split.stats.bad_checksum) << how;
    EXPECT_EQ(whole.stats.truncated, split.stats.truncated) << how;
    EXPECT_EQ(whole.stats.unknown_msgid, split.stats.unknown_msgid) << how;
    EXPECT_EQ(whole.stats.incompat_rejected, split.stats.incompat_rejected) << how;
    EXPECT_EQ(whole.stats.signed_frames, split.stats.signed_frames) << how;
    EXPECT_EQ(whole.stats.seq_lost, split.stats.seq_lost) << how;
}

void check_splits(const Bytes& bytes) {
    const SplitOutcome whole = run_split(bytes, [&] { return bytes.size() + 1; });
    for (const std::size_t size : {1u, 2u, 3u, 5u, 16u, 17u, 64u, 97u}) {
        expect_same(whole, run_split(bytes, [&] { return size; }),
                    ("reads of " + std::to_string(size)).c_str());
    }
    std::mt19937 rng(7);
    expect_same(whole, run_split(bytes, [&] { return std::size_t{rng() % 40}; }),
                "random reads, empty ones too");
}

TEST(MavlinkParserSplit, NoisyArdupilotStreamGivesTheSameFramesAndCountersHoweverRead) {
    test::LineNoise noise;
    noise.byte_error_rate = 2e-3;  // a damaged frame every few dozen: resynchronisation all the time
    const auto s = test::make_ardupilot_stream(400'000, 11, noise);
    const ParserStats whole = run_split(s.received, [&] { return s.received.size(); }).stats;
    ASSERT_GT(whole.bad_checksum, 0u);  // the stream does make the parser resynchronise
    ASSERT_GT(whole.truncated, 0u);
    ASSERT_GT(whole.unknown_msgid, 0u);
    check_splits(s.received);
}

TEST(MavlinkParserSplit, CleanArdupilotStreamGivesTheSameFramesHoweverRead) {
    const auto s = test::make_ardupilot_stream(200'000, 5, test::LineNoise{0.0, 0.0, 0.0});
    check_splits(s.received);
}

TEST(MavlinkParserSplit, FuzzSeedsGiveTheSameFramesAndCountersHoweverRead) {
    const std::filesystem::path dir =
        std::filesystem::path(::airseg::test::source_dir()) / "tests/fuzz/corpus/mavlink";
    std::size_t seeds = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().extension() != ".bin") {
            continue;
        }
        std::ifstream in(entry.path(), std::ios::binary);
        const Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        SCOPED_TRACE(entry.path().filename().string());
        check_splits(bytes);
        ++seeds;
    }
    EXPECT_GT(seeds, 0u);
}

}  // namespace
}  // namespace airseg::mavlink
