// Forward error correction of the ground link: the erasure code, the CRC-16 of a shard, shards through lost
// and corrupted bytes, the error-rate meter and the frame plan.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "services/groundlink/transport/cobs.hpp"
#include "services/groundlink/transport/crc16.hpp"
#include "services/groundlink/transport/erasure_code.hpp"
#include "services/groundlink/transport/error_rate_meter.hpp"
#include "services/groundlink/transport/fec_frame.hpp"
#include "services/groundlink/transport/fec_plan.hpp"

namespace airseg::groundlink {
namespace {

std::vector<std::vector<std::uint8_t>> random_shards(std::size_t n, std::size_t len, std::mt19937& rng) {
    std::vector<std::vector<std::uint8_t>> d(n, std::vector<std::uint8_t>(len));
    for (auto& s : d) {
        for (auto& b : s) {
            b = static_cast<std::uint8_t>(rng());
        }
    }
    return d;
}

TEST(GroundlinkFec, Crc16MatchesTheCcittFalseCheckValue) {
    const std::string check = "123456789";
    EXPECT_EQ(crc16_ccitt(std::span(reinterpret_cast<const std::uint8_t*>(check.data()), check.size())),
              0x29B1);
}

TEST(GroundlinkFec, AnyNOfTheShardsGiveTheDataBack) {
    std::mt19937 rng(7);
    for (const auto& [n, k] : {std::pair{1, 1}, {3, 2}, {10, 6}, {69, 47}, {128, 127}}) {
        const auto n_size = static_cast<std::size_t>(n);
        const auto data = random_shards(n_size, 17, rng);
        std::vector<std::span<const std::uint8_t>> views(data.begin(), data.end());
        std::vector<std::vector<std::uint8_t>> all = data;
        for (int j = 0; j < k; ++j) {
            all.push_back(fec::encode_parity(views, static_cast<std::size_t>(j)));
        }
        for (int trial = 0; trial < 20; ++trial) {
            std::vector<std::size_t> idx(all.size());
            std::iota(idx.begin(), idx.end(), 0);
            std::shuffle(idx.begin(), idx.end(), rng);
            idx.resize(n_size);  // exactly n survivors, any of them
            std::vector<fec::Shard> have;
            for (std::size_t i : idx) {
                have.push_back({i, all[i]});
            }
            const auto back = fec::reconstruct(n_size, have);
            ASSERT_TRUE(back.has_value()) << n << "+" << k;
            EXPECT_EQ(*back, data) << n << "+" << k << " trial " << trial;
        }
    }
}

TEST(GroundlinkFec, FewerThanNShardsOrMixedLengthsAreRefused) {
    std::mt19937 rng(3);
    const auto data = random_shards(4, 8, rng);
    std::vector<std::span<const std::uint8_t>> views(data.begin(), data.end());
    const auto p0 = fec::encode_parity(views, 0);
    std::vector<fec::Shard> three{{0, data[0]}, {1, data[1]}, {4, p0}};
    EXPECT_FALSE(fec::reconstruct(4, three).has_value());
    std::vector<fec::Shard> dup{{0, data[0]}, {0, data[0]}, {1, data[1]}, {4, p0}};
    EXPECT_FALSE(fec::reconstruct(4, dup).has_value());
    const std::vector<std::uint8_t> short_one(7, 0);
    std::vector<fec::Shard> mixed{{0, data[0]}, {1, data[1]}, {2, short_one}, {4, p0}};
    EXPECT_FALSE(fec::reconstruct(4, mixed).has_value());
}

// Shards of one frame through a byte stream that loses and flips bytes: the frame comes back whole once n
// shards survive, and nothing else comes back.
TEST(GroundlinkFec, AFrameSurvivesLostAndFlippedBytesThroughItsShards) {
    std::mt19937 rng(11);
    std::vector<std::uint8_t> frame(1000);
    for (auto& b : frame) {
        b = static_cast<std::uint8_t>(rng());
    }
    int rebuilt = 0;
    for (int trial = 0; trial < 30; ++trial) {
        const std::size_t shard = 15;
        const std::size_t n = fec::data_shards_for(frame.size(), shard);
        const double survival = std::pow(0.97, static_cast<double>(shard + fec::kShardOverhead));
        const std::size_t k = fec::parity_for(n, survival, 0.99);
        ASSERT_LE(n + k, fec::kMaxShards);
        std::vector<std::uint8_t> wire;
        fec::encode_frame(frame, static_cast<std::uint8_t>(trial), shard, k, wire);
        std::vector<std::uint8_t> damaged;
        std::bernoulli_distribution lose(0.02);
        std::bernoulli_distribution flip(0.01);
        for (std::uint8_t b : wire) {
            if (lose(rng)) {
                continue;
            }
            damaged.push_back(flip(rng) ? static_cast<std::uint8_t>(b ^ (1U << (rng() % 8))) : b);
        }
        fec::ShardAssembler assembler;
        CobsDeframer deframer(4096);
        std::vector<std::uint8_t> out;
        int complete = 0;
        deframer.feed(
            damaged,
            [&](std::vector<std::uint8_t>&& plain) {
                if (assembler.add(plain, TimePoint{}, out) == fec::ShardAssembler::Result::Complete) {
                    ++complete;
                    EXPECT_EQ(out, frame);
                }
            },
            [] {});
        EXPECT_LE(complete, 1);
        rebuilt += complete;
    }
    EXPECT_GE(rebuilt, 27);  // parity sized for 99 % per frame at 3 % byte errors
}

TEST(GroundlinkFec, TheMeterEstimatesTheByteErrorRateFromFramesOfAnySize) {
    std::mt19937 rng(5);
    for (const double p : {0.001, 0.01, 0.02, 0.05}) {
        ErrorRateMeter m;
        std::uniform_int_distribution<std::size_t> size(10, 400);
        for (int i = 0; i < 3000; ++i) {
            const std::size_t t = size(rng);
            std::bernoulli_distribution ok(std::pow(1.0 - p, static_cast<double>(t)));
            m.on_frame(t, ok(rng));
        }
        const auto est = m.byte_error_rate();
        ASSERT_TRUE(est.has_value());
        EXPECT_NEAR(*est, p, 0.25 * p) << "true rate " << p;
    }
    ErrorRateMeter clean;
    for (int i = 0; i < 100; ++i) {
        clean.on_frame(100, true);
    }
    EXPECT_EQ(clean.byte_error_rate(), 0.0);
    ErrorRateMeter fresh;
    fresh.on_frame(100, false);
    EXPECT_FALSE(fresh.byte_error_rate().has_value());
}

TEST(GroundlinkFec, FramesVanishingWholeMakeTheMeterBurstyAndBytesGoingBadDoNot) {
    std::mt19937 rng(9);
    std::bernoulli_distribution coin(0.3);
    // Air packets lost: about as many frames vanish as arrive damaged.
    ErrorRateMeter packets;
    for (int i = 0; i < 400; ++i) {
        const bool hit = coin(rng);
        packets.on_frame(180, !hit);
        if (hit) {
            packets.on_vanished(1);
        }
    }
    EXPECT_TRUE(packets.bursty());
    // Byte errors: a frame vanishes only when its delimiter is hit (merged into its neighbour, which
    // arrives damaged), about once in a frame's length of errors.
    ErrorRateMeter bytes;
    std::bernoulli_distribution delimiter(1.0 / 180.0);
    for (int i = 0; i < 4000; ++i) {
        const bool hit = coin(rng);
        bytes.on_frame(180, !hit);
        if (hit && delimiter(rng)) {
            bytes.on_vanished(1);
        }
    }
    EXPECT_FALSE(bytes.bursty());
    // A number that arrives after all (another path) takes its vanishing back.
    ErrorRateMeter late;
    for (int i = 0; i < 10; ++i) {
        late.on_frame(180, i % 2 == 0);
    }
    for (int i = 0; i < 4; ++i) {
        late.on_vanished(1);
    }
    EXPECT_TRUE(late.bursty());
    late.on_vanished(-1);
    late.on_vanished(-1);
    EXPECT_FALSE(late.bursty());
}

TEST(GroundlinkFec, AGroupOfShardsIsNeverLongerOnTheWireThanThreeOfTheLongestPlainFrames) {
    // Small shards with much parity are several times their frame on the wire, and a group is written at
    // once: a radio buffer that takes a few of the longest frames must take it.
    bool some_shards = false;
    for (const double p : {0.005, 0.01, 0.02, 0.05, 0.08}) {
        const auto plan = fec::plan_frames(p, 30, 16, 1024, true);
        if (!plan.fec) {
            continue;
        }
        some_shards = true;
        const std::size_t n = fec::data_shards_for(plan.payload + 28, plan.shard_bytes);
        const std::size_t k = fec::parity_for(n, plan.shard_survival);
        EXPECT_LE((n + k) * (plan.shard_bytes + fec::kShardOverhead), 3U * (1024U + 30U)) << "rate " << p;
    }
    EXPECT_TRUE(some_shards);
}

TEST(GroundlinkFec, ThePlanPicksPlainFramesOnGoodLinksAndShardsOnBadOnes) {
    const std::size_t overhead = 15;
    const auto clean = fec::plan_frames(0.0, overhead, 16, 1024, true);
    EXPECT_FALSE(clean.fec);
    EXPECT_EQ(clean.payload, 1024U);
    const auto good = fec::plan_frames(1e-5, overhead, 16, 1024, true);
    EXPECT_FALSE(good.fec);
    EXPECT_GT(good.payload, 500U);
    const auto bad = fec::plan_frames(0.02, overhead, 16, 1024, true);
    EXPECT_TRUE(bad.fec);
    EXPECT_GT(bad.efficiency, 0.3);
    const auto bad_no_fec = fec::plan_frames(0.02, overhead, 16, 1024, false);
    EXPECT_FALSE(bad_no_fec.fec);
    EXPECT_LT(bad_no_fec.payload, 40U);
    EXPECT_LT(bad_no_fec.efficiency, bad.efficiency);
    // Parity: none on a perfect link, more for worse shards.
    EXPECT_EQ(fec::parity_for(10, 1.0), 0U);
    EXPECT_LT(fec::parity_for(10, 0.9), fec::parity_for(10, 0.6));
}

}  // namespace
}  // namespace airseg::groundlink
