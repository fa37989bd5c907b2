#include "bench/linkbench/seed_protocol.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "tools/linksim/radio_model.hpp"

namespace airseg::linkbench::seed {
namespace {

const TimePoint kStart{};

std::vector<std::uint8_t> payload(std::size_t n, std::uint8_t salt) {
    std::vector<std::uint8_t> v(n);
    for (std::size_t i = 0; i < n; ++i) {
        v[i] = static_cast<std::uint8_t>(i * 13 + salt);  // includes DLE (0x10) and ETX (0x03) values
    }
    return v;
}

TEST(SeedProtocol, Crc32MatchesTheZlibCheckValue) {
    const std::string check = "123456789";
    EXPECT_EQ(crc32(std::span(reinterpret_cast<const std::uint8_t*>(check.data()), check.size())),
              0xCBF43926U);
}

TEST(SeedProtocol, FrameDoublesDleAndEndsWithDleEtx) {
    const std::vector<std::uint8_t> body{0x12, kDle, 0x00};
    const auto frame = encode_frame(body);
    ASSERT_GE(frame.size(), 4u + 4u + 3u);
    EXPECT_EQ(frame.front(), kDle);
    EXPECT_EQ(frame[1], 0x12);
    EXPECT_EQ(frame[2], kDle);
    EXPECT_EQ(frame[3], kDle);
    EXPECT_EQ(frame[frame.size() - 2], kDle);
    EXPECT_EQ(frame.back(), kEtx);
}

// Moves every frame from one end to the other directly, in the order written.
void pump(SeedEndpoint& from, SeedEndpoint& to, TimePoint now) {
    while (auto f = from.poll_transmit(now)) {
        to.handle_bytes(*f, now);
    }
}

TEST(SeedProtocol, SafeAndFastRoundTripOnACleanWire) {
    SeedEndpoint a;
    SeedEndpoint b;
    const auto big = payload(1000, 1);  // four fragments of at most 300 bytes
    const auto small = payload(40, 2);
    ASSERT_TRUE(a.send_safe(big, kStart));
    ASSERT_TRUE(a.send_fast(small, kStart));
    EXPECT_EQ(a.safe_pending(), 1u);
    pump(a, b, kStart);
    auto m1 = b.poll_message();
    ASSERT_TRUE(m1);
    EXPECT_TRUE(m1->safe);
    EXPECT_EQ(m1->bytes, big);
    auto m2 = b.poll_message();
    ASSERT_TRUE(m2);
    EXPECT_FALSE(m2->safe);
    EXPECT_EQ(m2->bytes, small);
    EXPECT_FALSE(b.poll_message());
    EXPECT_EQ(b.stats().acks_sent, 4u);
    pump(b, a, kStart);
    EXPECT_EQ(a.safe_pending(), 0u);
    EXPECT_EQ(a.poll_timeout(), kNever);
}

TEST(SeedProtocol, LostFragmentIsResentAfterTheFixedTimeout) {
    SeedEndpoint a;
    SeedEndpoint b;
    const auto msg = payload(500, 3);
    a.send_safe(msg, kStart);
    auto first = a.poll_transmit(kStart);  // fragment 1: lost on the way
    ASSERT_TRUE(first);
    pump(a, b, kStart);
    pump(b, a, kStart);
    EXPECT_FALSE(b.poll_message());
    EXPECT_EQ(a.poll_timeout(), kStart + std::chrono::milliseconds(1500));
    a.handle_timeout(kStart + std::chrono::milliseconds(1500));
    pump(a, b, kStart + std::chrono::milliseconds(1500));
    auto m = b.poll_message();
    ASSERT_TRUE(m);
    EXPECT_EQ(m->bytes, msg);
    EXPECT_EQ(a.stats().resent_on_timeout, 1u);
}

TEST(SeedProtocol, CorruptedSafeFrameIsNackedAndResentAtOnce) {
    SeedEndpoint a;
    SeedEndpoint b;
    const auto msg = payload(100, 4);
    a.send_safe(msg, kStart);
    auto frame = a.poll_transmit(kStart);
    ASSERT_TRUE(frame);
    (*frame)[20] ^= 0x40;  // inside the data, clear of any DLE
    b.handle_bytes(*frame, kStart);
    EXPECT_EQ(b.stats().crc_errors, 1u);
    EXPECT_EQ(b.stats().nacks_sent, 1u);
    pump(b, a, kStart);
    EXPECT_EQ(a.stats().resent_on_nack, 1u);
    pump(a, b, kStart);
    auto m = b.poll_message();
    ASSERT_TRUE(m);
    EXPECT_EQ(m->bytes, msg);
}

TEST(SeedProtocol, FastQueueKeepsTheNewestTwenty) {
    SeedEndpoint a;
    SeedEndpoint b;
    for (std::uint8_t i = 0; i < 25; ++i) {
        a.send_fast(std::vector<std::uint8_t>{i}, kStart);
    }
    EXPECT_EQ(a.stats().fast_dropped_queue, 5u);
    pump(a, b, kStart);
    auto first = b.poll_message();
    ASSERT_TRUE(first);
    EXPECT_EQ(first->bytes, std::vector<std::uint8_t>{5});
}

TEST(SeedProtocol, RoundTripThroughACleanRadioPair) {
    linksim::RadioConfig rc;
    rc.duplex = linksim::Duplex::Full;
    linksim::RadioModel radio(rc, kStart);
    SeedEndpoint a;
    SeedEndpoint b;
    std::vector<std::vector<std::uint8_t>> sent;
    for (std::uint8_t i = 0; i < 5; ++i) {
        sent.push_back(payload(700, i));
        a.send_safe(sent.back(), kStart);
    }
    std::vector<std::vector<std::uint8_t>> got;
    std::vector<std::uint8_t> pending_a;
    std::vector<std::uint8_t> pending_b;
    for (TimePoint now = kStart; now < kStart + std::chrono::seconds(5);
         now += std::chrono::milliseconds(1)) {
        b.handle_bytes(radio.poll_output(linksim::Side::B, now), now);
        a.handle_bytes(radio.poll_output(linksim::Side::A, now), now);
        a.handle_timeout(now);
        b.handle_timeout(now);
        while (auto m = b.poll_message()) {
            got.push_back(m->bytes);
        }
        for (auto [end, side, pending] :
             {std::tuple{&a, linksim::Side::A, &pending_a}, {&b, linksim::Side::B, &pending_b}}) {
            while (auto f = end->poll_transmit(now)) {
                pending->insert(pending->end(), f->begin(), f->end());
            }
            const auto n = radio.push(side, *pending, now);
            pending->erase(pending->begin(), pending->begin() + static_cast<std::ptrdiff_t>(n));
        }
    }
    EXPECT_EQ(got, sent);
    EXPECT_EQ(a.safe_pending(), 0u);
    EXPECT_EQ(a.stats().resent_on_timeout, 0u);
    EXPECT_EQ(b.stats().crc_errors, 0u);
}

}  // namespace
}  // namespace airseg::linkbench::seed
