#include "tools/linksim/radio_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace airseg::linksim {
namespace {

const TimePoint kStart{};

std::vector<std::uint8_t> pattern(std::size_t n, std::uint8_t seed = 0) {
    std::vector<std::uint8_t> v(n);
    for (std::size_t i = 0; i < n; ++i) {
        v[i] = static_cast<std::uint8_t>(i * 7 + seed);
    }
    return v;
}

// Drives the model in 1 ms steps of simulated time. Each side writes `source` as fast as its UART accepts.
struct Drive {
    Drive(RadioModel& m, std::vector<std::uint8_t> from_a, std::vector<std::uint8_t> from_b)
        : model(m), source{std::move(from_a), std::move(from_b)} {}

    RadioModel& model;
    std::array<std::vector<std::uint8_t>, 2> source;
    std::array<std::size_t, 2> written{0, 0};
    std::array<std::vector<std::uint8_t>, 2> received;  // indexed by receiving side

    void run(Duration length, Duration step = milliseconds(1)) {
        const TimePoint end = model.start() + length;
        for (TimePoint now = model.start(); now <= end; now += step) {
            for (Side s : {Side::A, Side::B}) {
                auto& src = source[index(s)];
                auto& w = written[index(s)];
                if (w < src.size()) {
                    w += model.push(s, std::span(src).subspan(w), now);
                }
                auto out = model.poll_output(s, now);
                received[index(s)].insert(received[index(s)].end(), out.begin(), out.end());
            }
        }
    }
};

RadioConfig clean(Duplex duplex) {
    RadioConfig c;
    c.duplex = duplex;
    return c;
}

TEST(RadioModel, DeliversNoFasterThanTheSerialRate) {
    RadioModel model(clean(Duplex::Full), kStart);
    Drive drive(model, pattern(200'000), {});
    drive.run(seconds(10));
    const double limit = 57600 / 10.0 * 10.0;
    const auto got = drive.received[index(Side::B)].size();
    EXPECT_LE(got, limit);
    EXPECT_GE(got, 0.97 * limit) << "a clean link should run close to line rate";
    // Clean link: every byte arrives unchanged and in order.
    const auto& src = drive.source[index(Side::A)];
    EXPECT_TRUE(std::equal(drive.received[index(Side::B)].begin(), drive.received[index(Side::B)].end(),
                           src.begin()));
    EXPECT_EQ(model.stats(Side::A).overflow_dropped, 0u);
}

TEST(RadioModel, AirRateBelowSerialRateLimitsDelivery) {
    RadioConfig c = clean(Duplex::Full);
    c.air_rate_bps = 16000;  // 2000 bytes/s on air, 5760 bytes/s on the serial line
    c.radio_buffer = 1024;
    RadioModel model(c, kStart);
    Drive drive(model, pattern(100'000), {});
    drive.run(seconds(5));
    const auto got = drive.received[index(Side::B)].size();
    EXPECT_LE(got, 2000 * 5);
    EXPECT_GE(got, 0.9 * 2000 * 5);
    const auto& st = model.stats(Side::A);
    EXPECT_GT(st.overflow_dropped, 10'000u) << "a radio without flow control drops what its air cannot carry";
}

TEST(RadioModel, OverflowAccountsForEveryByte) {
    RadioConfig c = clean(Duplex::Full);
    c.air_rate_bps = 8000;
    c.radio_buffer = 300;
    RadioModel model(c, kStart);
    Drive drive(model, pattern(20'000), {});
    drive.run(seconds(30));
    const auto& st = model.stats(Side::A);
    EXPECT_EQ(st.bytes_in, 20'000u);
    EXPECT_GT(st.overflow_dropped, 0u);
    EXPECT_EQ(st.bytes_out + st.overflow_dropped, st.bytes_in);
}

TEST(RadioModel, HalfDuplexSharesTheAirBetweenDirections) {
    RadioModel half(clean(Duplex::Half), kStart);
    Drive hd(half, pattern(200'000, 1), pattern(200'000, 2));
    hd.run(seconds(10));
    const double line = 5760.0 * 10.0;
    const auto ab = hd.received[index(Side::B)].size();
    const auto ba = hd.received[index(Side::A)].size();
    EXPECT_LE(ab + ba, line) << "one air channel carries at most the air rate in total";
    EXPECT_GE(ab + ba, 0.9 * line);
    EXPECT_NEAR(static_cast<double>(ab) / static_cast<double>(ab + ba), 0.5, 0.05);
    EXPECT_GT(half.air_utilisation(Side::A, kStart + seconds(10)), 0.9);

    RadioModel full(clean(Duplex::Full), kStart);
    Drive fd(full, pattern(200'000, 1), pattern(200'000, 2));
    fd.run(seconds(10));
    EXPECT_GE(fd.received[index(Side::B)].size(), 0.95 * line);
    EXPECT_GE(fd.received[index(Side::A)].size(), 0.95 * line);
}

TEST(RadioModel, TurnaroundCostsAirTime) {
    RadioConfig c = clean(Duplex::Half);
    c.turnaround = milliseconds(20);
    RadioModel model(c, kStart);
    Drive drive(model, pattern(200'000, 1), pattern(200'000, 2));
    drive.run(seconds(10));
    const auto total = drive.received[0].size() + drive.received[1].size();
    // 252-byte packets take 43.75 ms at 5760 B/s; a 20 ms switch after each costs about a third of the air.
    EXPECT_LT(total, 0.75 * 57600.0);
    EXPECT_GT(total, 0.6 * 57600.0);
}

TEST(RadioModel, HostUartRefusesBeyondItsBuffer) {
    RadioConfig c = clean(Duplex::Full);
    c.host_buffer = 100;
    RadioModel model(c, kStart);
    auto data = pattern(250);
    EXPECT_EQ(model.push(Side::A, data, kStart), 100u);
    EXPECT_EQ(model.serial_space(Side::A, kStart), 0u);
    EXPECT_EQ(model.stats(Side::A).bytes_refused, 150u);
    // 50 byte times later the UART has shifted 50 bytes into the radio.
    EXPECT_EQ(model.serial_space(Side::A, kStart + std::chrono::nanoseconds(50 * 173612)), 50u);
}

TEST(RadioModel, SingleByteLatencyIsSerialPlusAirPlusConfigured) {
    RadioConfig c = clean(Duplex::Full);
    c.impairment[index(Side::A)].latency = milliseconds(30);
    RadioModel model(c, kStart);
    const std::uint8_t byte[] = {0x42};
    model.push(Side::A, byte, kStart);
    const TimePoint due = model.poll_timeout();
    EXPECT_EQ(due - kStart, std::chrono::nanoseconds(173612));  // the byte reaches the radio: air can start
    TimePoint now = kStart;
    std::vector<std::uint8_t> got;
    while (got.empty()) {
        now = model.poll_timeout();
        ASSERT_NE(now, kNever);
        got = model.poll_output(Side::B, now);
    }
    // serial in (173.6 us) + air (173.6 us) + latency (30 ms) + serial out (173.6 us)
    const double elapsed_ms = std::chrono::duration<double, std::milli>(now - kStart).count();
    EXPECT_NEAR(elapsed_ms, 30.52, 0.01);
    EXPECT_EQ(got, std::vector<std::uint8_t>{0x42});
    EXPECT_EQ(model.poll_timeout(), kNever);
}

struct Piece {
    TimePoint at;
    std::vector<std::uint8_t> bytes;
};

// Every hand-over to host `to`, at the instants the model announces, until nothing is left in flight.
std::vector<Piece> pieces_for(RadioModel& model, Side to) {
    std::vector<Piece> pieces;
    for (TimePoint now = model.poll_timeout(); now != kNever; now = model.poll_timeout()) {
        if (auto out = model.poll_output(to, now); !out.empty()) {
            pieces.push_back({now, std::move(out)});
        }
    }
    return pieces;
}

Duration since_start(TimePoint t) {
    return t - kStart;
}

// Host B reaches its radio through a USB adapter with a 16-ms latency timer, host A through a bare UART.
// `from` writes `bytes` at the start; returns what the other host receives, piece by piece.
std::vector<Piece> through_b_adapter(Side from, const std::vector<std::uint8_t>& bytes) {
    RadioConfig c = clean(Duplex::Full);
    c.usb_latency[index(Side::B)] = milliseconds(16);
    RadioModel model(c, kStart);
    model.push(from, bytes, kStart);
    return pieces_for(model, other(from));
}

TEST(RadioModel, UsbAdapterHandsAShortFrameOverWholeWhenItsLatencyTimerExpires) {
    const auto frame = pattern(20);
    const auto pieces = through_b_adapter(Side::A, frame);
    ASSERT_EQ(pieces.size(), 1u) << "a 20-byte frame fits one USB packet";
    EXPECT_EQ(pieces[0].bytes, frame);
    // The last byte leaves the UART after 20 bytes in, air and 20 bytes out (about 7.1 ms); the timer,
    // running since the start, expires at 16 ms.
    EXPECT_EQ(since_start(pieces[0].at), milliseconds(16));
}

TEST(RadioModel, UsbAdapterSendsAFullPacketAtOnceAndLessOnlyWhenItsTimerExpires) {
    const auto data = pattern(400);
    const auto pieces = through_b_adapter(Side::A, data);
    std::vector<std::uint8_t> joined;
    std::size_t full = 0;
    TimePoint timer_start = kStart;  // the timer restarts at every packet
    for (std::size_t i = 0; i < pieces.size(); ++i) {
        const auto& p = pieces[i];
        ASSERT_LE(p.bytes.size(), 62u) << "piece " << i;
        if (p.bytes.size() == 62) {
            ++full;
            EXPECT_LT(p.at - timer_start, milliseconds(16)) << "a full packet does not wait for the timer";
        } else {
            EXPECT_EQ((p.at - timer_start) % milliseconds(16), Duration::zero())
                << "piece " << i << " of " << p.bytes.size() << " bytes left between two expiries";
        }
        timer_start = p.at;
        joined.insert(joined.end(), p.bytes.begin(), p.bytes.end());
    }
    EXPECT_EQ(joined, data);
    // 62 bytes take 10.8 ms at 57600 baud, less than the timer: a steady stream goes in full packets.
    EXPECT_GE(full, 4u);
    EXPECT_LE(pieces.size(), 8u);
}

TEST(RadioModel, WithoutAnAdapterBytesReachTheHostAsTheyLeaveTheUart) {
    // Host B's adapter does not change what A receives.
    const auto pieces = through_b_adapter(Side::B, pattern(20));
    ASSERT_EQ(pieces.size(), 20u) << "one hand-over per byte";
    const double gap_ms = std::chrono::duration<double, std::milli>(pieces[1].at - pieces[0].at).count();
    EXPECT_NEAR(gap_ms, 0.1736, 0.001);
}

std::vector<std::uint8_t> run_impaired(std::uint64_t seed) {
    RadioConfig c = clean(Duplex::Half);
    c.seed = seed;
    c.impairment[index(Side::A)].byte_loss = 0.01;
    c.impairment[index(Side::A)].byte_corruption = 0.01;
    c.impairment[index(Side::A)].frame_loss = 0.05;
    RadioModel model(c, kStart);
    Drive drive(model, pattern(30'000), pattern(5'000));
    drive.run(seconds(5));
    return drive.received[index(Side::B)];
}

TEST(RadioModel, SameSeedSameBytesDifferentSeedDifferentBytes) {
    const auto first = run_impaired(7);
    EXPECT_EQ(first, run_impaired(7));
    EXPECT_NE(first, run_impaired(8));
}

TEST(RadioModel, ImpairmentRatesMatchConfiguration) {
    RadioConfig c = clean(Duplex::Full);
    c.seed = 3;
    c.impairment[index(Side::A)].byte_loss = 0.02;
    c.impairment[index(Side::A)].byte_corruption = 0.05;
    RadioModel model(c, kStart);
    Drive drive(model, pattern(50'000), {});
    drive.run(seconds(10));
    const auto& st = model.stats(Side::A);
    ASSERT_EQ(st.bytes_in, 50'000u);
    EXPECT_NEAR(static_cast<double>(st.bytes_lost) / 50'000.0, 0.02, 0.004);
    EXPECT_NEAR(static_cast<double>(st.bytes_corrupted) / 50'000.0, 0.05 * 0.98, 0.006);
    EXPECT_EQ(st.bytes_out, 50'000u - st.bytes_lost);
}

TEST(RadioModel, BitErrorRateFlipsBitsAtThatRate) {
    RadioConfig c = clean(Duplex::Full);
    c.seed = 11;
    c.impairment[index(Side::A)].bit_error_rate = 0.01;
    RadioModel model(c, kStart);
    const auto sent = pattern(40'000);
    Drive drive(model, sent, {});
    drive.run(seconds(8));
    const auto& got = drive.received[index(Side::B)];
    ASSERT_EQ(got.size(), sent.size());
    std::size_t flipped = 0;
    for (std::size_t i = 0; i < got.size(); ++i) {
        flipped += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(got[i] ^ sent[i])));
    }
    EXPECT_NEAR(static_cast<double>(flipped) / (8.0 * 40'000.0), 0.01, 0.001);
    EXPECT_NEAR(static_cast<double>(model.stats(Side::A).bytes_corrupted) / 40'000.0, 1.0 - std::pow(0.99, 8),
                0.006);
}

TEST(RadioModel, OutageLosesOnlyPacketsInsideIt) {
    RadioConfig c = clean(Duplex::Full);
    c.impairment[index(Side::A)].outages.push_back({seconds(1), seconds(2)});
    RadioModel model(c, kStart);
    std::vector<std::size_t> per_100ms;
    const auto data = pattern(100'000);
    std::size_t written = 0;
    std::size_t bucket = 0;
    for (TimePoint now = kStart; now <= kStart + seconds(5); now += milliseconds(1)) {
        written += model.push(Side::A, std::span(data).subspan(written), now);
        bucket += model.poll_output(Side::B, now).size();
        if ((now - kStart) % milliseconds(100) == Duration::zero()) {
            per_100ms.push_back(bucket);
            bucket = 0;
        }
    }
    // Index i covers ((i-1)*100 ms, i*100 ms]. Allow one packet time plus output for the edges.
    for (std::size_t i = 12; i <= 30; ++i) {
        EXPECT_EQ(per_100ms[i], 0u) << "delivered inside the outage at " << i * 100 << " ms";
    }
    EXPECT_GT(per_100ms[5], 400u);
    EXPECT_GT(per_100ms[35], 400u);
    EXPECT_GT(model.stats(Side::A).outage_packets_lost, 30u);
}

TEST(RadioModel, RadioDownDropsAndRecovers) {
    RadioModel model(clean(Duplex::Full), kStart);
    const auto data = pattern(100);
    model.set_radio_down(Side::B, true, kStart);
    model.push(Side::A, data, kStart);
    EXPECT_TRUE(model.poll_output(Side::B, kStart + seconds(1)).empty());
    model.push(Side::B, data, kStart + seconds(1));
    EXPECT_EQ(model.stats(Side::B).down_dropped, 100u);
    model.set_radio_down(Side::B, false, kStart + seconds(1));
    model.push(Side::A, data, kStart + seconds(1));
    EXPECT_EQ(model.poll_output(Side::B, kStart + seconds(2)), data);
}

TEST(RadioModel, RejectsInvalidConfigurationWithTheFieldName) {
    RadioConfig c;
    c.impairment[index(Side::B)].frame_loss = 1.5;
    try {
        RadioModel model(c, kStart);
        FAIL() << "accepted frame_loss 1.5";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("b->a"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("frame_loss"), std::string::npos) << e.what();
    }
    c = RadioConfig{};
    c.baud = 0;
    EXPECT_NE(c.validate().find("baud"), std::string::npos);
    c = RadioConfig{};
    c.usb_latency[index(Side::A)] = milliseconds(256);
    EXPECT_NE(c.validate().find("usb_latency of host a"), std::string::npos) << c.validate();
    c = RadioConfig{};
    c.usb_packet = 0;
    EXPECT_NE(c.validate().find("usb_packet"), std::string::npos) << c.validate();
}

}  // namespace
}  // namespace airseg::linksim
