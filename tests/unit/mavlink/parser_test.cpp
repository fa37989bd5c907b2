// Parser recovery and accounting: noise, damaged and cut-short frames, flags, signatures, unknown ids,
// sequence gaps, arbitrary chunking.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/support/tree_paths.hpp"
#include "tests/unit/mavlink/golden_frames.hpp"

namespace airseg::mavlink {
namespace {

using Bytes = std::vector<std::uint8_t>;

struct Collected {
    std::vector<Frame> frames;
    ParserStats stats;
};

Collected run(const Bytes& bytes, std::size_t chunk = 0) {
    Parser parser;
    Collected c;
    auto sink = [&](const Frame& f) { c.frames.push_back(f); };
    if (chunk == 0) {
        parser.push(bytes, sink);
    } else {
        for (std::size_t i = 0; i < bytes.size(); i += chunk) {
            parser.push(std::span(bytes).subspan(i, std::min(chunk, bytes.size() - i)), sink);
        }
    }
    parser.finish(sink);
    c.stats = parser.stats();
    return c;
}

Bytes heartbeat_frame(Encoder& e, std::uint32_t custom_mode = 0) {
    Heartbeat hb;
    hb.custom_mode = custom_mode;
    return e.encode(hb);
}

Bytes concat(std::initializer_list<Bytes> parts) {
    Bytes out;
    for (const Bytes& p : parts) {
        out.insert(out.end(), p.begin(), p.end());
    }
    return out;
}

// A frame of a message id this implementation does not know (CRC_EXTRA 0 stands in for the real one).
Bytes unknown_frame(std::uint32_t msgid, Bytes payload, std::uint8_t seq = 0) {
    std::array<std::uint8_t, kMaxFrameLength> out{};
    const std::size_t n = encode_frame(FrameHeader{Version::V2, seq, 1, 1, msgid, 0}, 0, payload, out);
    return Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
}

// A HEARTBEAT with a chosen sequence number (0xFD or 0xFE makes a start byte inside the frame).
Bytes heartbeat_with_seq(std::uint8_t seq, std::uint32_t custom_mode) {
    Heartbeat hb;
    hb.custom_mode = custom_mode;
    std::array<std::uint8_t, kMaxPayload> payload{};
    const std::size_t length = encode_payload(hb, payload);
    std::array<std::uint8_t, kMaxFrameLength> out{};
    const std::size_t n =
        encode_message(FrameHeader{Version::V2, seq, 1, 1, Heartbeat::kId, 0}, *find_message(Heartbeat::kId),
                       std::span(payload).first(length), out);
    return Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
}

// The custom_mode of each HEARTBEAT delivered, and which frames were unverified.
std::vector<std::uint32_t> heartbeats(const Collected& c) {
    std::vector<std::uint32_t> out;
    for (const Frame& f : c.frames) {
        if (auto hb = decode<Heartbeat>(f)) {
            out.push_back(hb->custom_mode);
        }
    }
    return out;
}

TEST(MavlinkParser, GarbageBetweenFramesIsSkippedAndCounted) {
    Encoder e(1, 1);
    const Bytes stream =
        concat({Bytes{0x00, 0x11, 0x22}, heartbeat_frame(e, 1), Bytes{0x33, 0x44}, heartbeat_frame(e, 2)});
    const auto c = run(stream);
    ASSERT_EQ(c.frames.size(), 2u);
    EXPECT_EQ(decode<Heartbeat>(c.frames[1])->custom_mode, 2u);
    EXPECT_EQ(c.stats.frames_ok, 2u);
    EXPECT_EQ(c.stats.garbage_bytes, 5u);
    EXPECT_EQ(c.stats.bad_checksum, 0u);
    EXPECT_EQ(c.stats.truncated, 0u);
}

TEST(MavlinkParser, ByteByByteAndBulkGiveTheSameResult) {
    Encoder e(1, 1);
    std::mt19937 rng(42);
    Bytes stream;
    for (int i = 0; i < 50; ++i) {
        const Bytes f = heartbeat_frame(e, static_cast<std::uint32_t>(i));
        stream.insert(stream.end(), f.begin(), f.end());
        for (int g = static_cast<int>(rng() % 4); g > 0; --g) {
            stream.push_back(static_cast<std::uint8_t>(rng() % 0xFD));  // noise that is never a start byte
        }
    }
    const auto bulk = run(stream);
    ASSERT_EQ(bulk.frames.size(), 50u);
    for (std::size_t chunk : {1u, 2u, 3u, 7u, 64u}) {
        const auto chunked = run(stream, chunk);
        ASSERT_EQ(chunked.frames.size(), bulk.frames.size()) << chunk;
        for (std::size_t i = 0; i < bulk.frames.size(); ++i) {
            EXPECT_EQ(decode<Heartbeat>(chunked.frames[i]), decode<Heartbeat>(bulk.frames[i]));
        }
        EXPECT_EQ(chunked.stats.garbage_bytes, bulk.stats.garbage_bytes) << chunk;
    }
}

// A good frame completes inside a long candidate while an earlier damaged stretch is still open, with another
// damaged frame between them. The long candidate is given up for the good frame; the bytes before it count as
// if each start byte there had been judged in turn: two damaged stretches, the rest garbage. Found by
// fuzzing: when the good frame was found before the long candidate was complete (the stream in pieces), the
// open stretch swallowed the damaged frame in between, and the counters depended on the split.
TEST(MavlinkParser, GoodFrameInsideALongCandidateCountsTheSameWholeAndInPieces) {
    Encoder e(1, 1);
    Bytes first = heartbeat_frame(e, 1);
    first[5] = kMagicV1;  // the damage: inside this frame a MAVLink 1 start byte...
    first[6] = 0xFF;      // ...claiming 255 bytes of payload, a 263-byte candidate
    Bytes second = heartbeat_frame(e, 2);
    second[12] ^= 0x01;  // inside the long candidate: a damaged frame of its own, after the first one
    const Bytes good = heartbeat_frame(e, 3);
    const Bytes noise(10, 0x55);
    Bytes stream = concat({first, noise, second, noise, good});
    stream.resize(300, 0x55);  // the long candidate is complete well before the stream ends
    ASSERT_LT(5 + 263, stream.size());

    const auto whole = run(stream);
    ASSERT_EQ(whole.frames.size(), 1u);
    EXPECT_EQ(decode<Heartbeat>(whole.frames[0])->custom_mode, 3u);
    EXPECT_EQ(whole.stats.frames_ok, 1u);
    EXPECT_EQ(whole.stats.bad_checksum, 2u);  // the first frame and the second one, each once
    EXPECT_EQ(whole.stats.truncated, 0u);     // both damaged stretches end before the good frame
    EXPECT_EQ(whole.stats.garbage_bytes, stream.size() - first.size() - second.size() - good.size());
    for (std::size_t chunk = 1; chunk <= 97; ++chunk) {
        const auto chunked = run(stream, chunk);
        ASSERT_EQ(chunked.frames.size(), 1u) << chunk;
        EXPECT_EQ(decode<Heartbeat>(chunked.frames[0])->custom_mode, 3u) << chunk;
        EXPECT_EQ(chunked.stats.frames_ok, whole.stats.frames_ok) << chunk;
        EXPECT_EQ(chunked.stats.bad_checksum, whole.stats.bad_checksum) << chunk;
        EXPECT_EQ(chunked.stats.truncated, whole.stats.truncated) << chunk;
        EXPECT_EQ(chunked.stats.garbage_bytes, whole.stats.garbage_bytes) << chunk;
    }
}

// An unknown-id frame followed by a start byte would be delivered unverified, but a verified frame completes
// inside it first. Byte by byte, the verified frame is found before the unknown one is complete; fed whole,
// the parser must come to the same result: the verified frame wins, the unknown frame counts as cut short.
TEST(MavlinkParser, VerifiedFrameInsideAnUnknownFrameWinsWholeAndInPieces) {
    Encoder e(1, 1);
    const Bytes inner = heartbeat_frame(e, 7);
    Bytes payload(5, 0x11);
    payload.insert(payload.end(), inner.begin(), inner.end());
    payload.resize(payload.size() + 5, 0x22);
    const Bytes stream = concat({unknown_frame(12345, payload), heartbeat_frame(e, 8)});
    for (std::size_t chunk = 0; chunk <= 97; ++chunk) {
        const auto c = run(stream, chunk);
        ASSERT_EQ(c.frames.size(), 2u) << chunk;
        EXPECT_EQ(decode<Heartbeat>(c.frames[0])->custom_mode, 7u) << chunk;
        EXPECT_EQ(decode<Heartbeat>(c.frames[1])->custom_mode, 8u) << chunk;
        EXPECT_EQ(c.stats.unknown_msgid, 0u) << chunk;
        EXPECT_EQ(c.stats.frames_ok, 2u) << chunk;
        EXPECT_EQ(c.stats.truncated, 1u) << chunk;
        EXPECT_EQ(c.stats.bad_checksum, 0u) << chunk;
        // The rest of the unknown frame after the verified one, its checksum included.
        EXPECT_EQ(c.stats.garbage_bytes, 7u) << chunk;
    }
}

// The input the fuzz target found (tests/fuzz/corpus/mavlink/), replayed here with its chunk size and others.
TEST(MavlinkParser, FuzzFoundStreamCountsTheSameWholeAndInPieces) {
    std::ifstream in(
        ::airseg::test::source_dir() + "/tests/fuzz/corpus/mavlink/counters_resync_inside_open_damage.bin",
        std::ios::binary);
    const Bytes stream{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    ASSERT_EQ(stream.size(), 585u);
    const auto whole = run(stream);
    EXPECT_EQ(whole.stats.frames_ok, 4u);
    for (std::size_t chunk = 1; chunk <= 97; ++chunk) {
        const auto chunked = run(stream, chunk);
        ASSERT_EQ(chunked.frames.size(), whole.frames.size()) << chunk;
        EXPECT_EQ(chunked.stats.frames_ok, whole.stats.frames_ok) << chunk;
        EXPECT_EQ(chunked.stats.bad_checksum, whole.stats.bad_checksum) << chunk;
        EXPECT_EQ(chunked.stats.truncated, whole.stats.truncated) << chunk;
        EXPECT_EQ(chunked.stats.garbage_bytes, whole.stats.garbage_bytes) << chunk;
        EXPECT_EQ(chunked.stats.seq_lost, whole.stats.seq_lost) << chunk;
    }
}

TEST(MavlinkParser, BadChecksumIsCountedAndTheNextFrameFound) {
    Encoder e(1, 1);
    Bytes damaged = heartbeat_frame(e, 1);
    damaged[12] ^= 0x01;
    const auto c = run(concat({damaged, heartbeat_frame(e, 2)}));
    ASSERT_EQ(c.frames.size(), 1u);
    EXPECT_EQ(decode<Heartbeat>(c.frames[0])->custom_mode, 2u);
    EXPECT_EQ(c.stats.bad_checksum, 1u);
    EXPECT_EQ(c.stats.truncated, 0u);
    EXPECT_EQ(c.stats.garbage_bytes, 0u);
}

TEST(MavlinkParser, FrameStartingInsideACutShortFrameIsRecovered) {
    Encoder e(1, 1);
    Bytes cut = heartbeat_frame(e, 1);
    cut.resize(8);  // the radio lost the rest of this frame
    const auto c = run(concat({cut, heartbeat_frame(e, 2), heartbeat_frame(e, 3)}));
    ASSERT_EQ(c.frames.size(), 2u);
    EXPECT_EQ(decode<Heartbeat>(c.frames[0])->custom_mode, 2u);
    EXPECT_EQ(decode<Heartbeat>(c.frames[1])->custom_mode, 3u);
    EXPECT_EQ(c.stats.truncated, 1u);
    EXPECT_EQ(c.stats.bad_checksum, 0u);
}

TEST(MavlinkParser, StreamEndingInsideAFrameCountsTruncated) {
    Encoder e(1, 1);
    Bytes cut = heartbeat_frame(e, 1);
    cut.resize(cut.size() - 3);
    const auto c = run(concat({heartbeat_frame(e, 0), cut}));
    EXPECT_EQ(c.frames.size(), 1u);
    EXPECT_EQ(c.stats.truncated, 1u);
    EXPECT_EQ(c.stats.garbage_bytes, 0u);
}

TEST(MavlinkParser, LengthByteCorruptedToHugeDoesNotHideLaterFrames) {
    Encoder e(1, 1);
    Bytes bad = heartbeat_frame(e, 1);
    bad[1] = 0xFF;  // claims 255 bytes of payload
    Bytes stream = bad;
    for (int i = 0; i < 20; ++i) {
        const Bytes f = heartbeat_frame(e, 100 + static_cast<std::uint32_t>(i));
        stream.insert(stream.end(), f.begin(), f.end());
    }
    const auto c = run(stream);
    ASSERT_EQ(c.frames.size(), 20u);
    EXPECT_EQ(decode<Heartbeat>(c.frames[0])->custom_mode, 100u);
}

TEST(MavlinkParser, GoodFrameInsideAnIncompleteCandidateIsDeliveredWithoutWaiting) {
    // A lost byte made the candidate's length come from the wrong byte: it claims far more bytes than the
    // line will carry for a while. The good frame behind it must not wait for those bytes.
    Encoder e(1, 1);
    Bytes bad = heartbeat_frame(e, 1);
    bad.erase(bad.begin() + 1);  // the length byte is lost: the sequence byte becomes the length
    bad[1] = 0xF0;
    Bytes stream = concat({bad, heartbeat_frame(e, 7)});
    Parser parser;
    std::vector<Frame> frames;
    parser.push(stream, [&](const Frame& f) { frames.push_back(f); });  // no finish(): the line is quiet
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(decode<Heartbeat>(frames[0])->custom_mode, 7u);
    EXPECT_EQ(parser.stats().truncated, 1u);

    // Byte by byte, the same.
    Parser slow;
    std::vector<Frame> slow_frames;
    for (std::uint8_t b : stream) {
        slow.push(std::span(&b, 1), [&](const Frame& f) { slow_frames.push_back(f); });
    }
    ASSERT_EQ(slow_frames.size(), 1u);
    EXPECT_EQ(decode<Heartbeat>(slow_frames[0])->custom_mode, 7u);
}

TEST(MavlinkParser, UnknownIncompatibilityFlagsAreRejectedCompatFlagsIgnored) {
    auto frame_with_flags = [](std::uint8_t incompat, std::uint8_t compat) {
        // Build by hand: the encoder never sets incompatibility flags.
        std::array<std::uint8_t, kMaxFrameLength> out{};
        std::array<std::uint8_t, 2> payload{0x07, 0x00};
        const auto* info = find_message(MissionItemReached::kId);
        FrameHeader h{Version::V2, 0, 1, 1, MissionItemReached::kId, compat};
        std::size_t n = encode_frame(h, info->crc_extra, payload, out);
        out[2] = incompat;
        Crc16 crc;
        crc.add(std::span<const std::uint8_t>(out.data() + 1, n - 3));
        crc.add(info->crc_extra);
        wire::put(out.data() + n - 2, crc.value());
        return Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
    };
    const auto c = run(concat({frame_with_flags(0x02, 0), frame_with_flags(0, 0xFF)}));
    ASSERT_EQ(c.frames.size(), 1u);
    EXPECT_EQ(c.frames[0].compat_flags, 0xFF);
    EXPECT_EQ(decode<MissionItemReached>(c.frames[0])->seq, 7);
    EXPECT_EQ(c.stats.incompat_rejected, 1u);
    EXPECT_EQ(c.stats.frames_ok, 1u);
}

TEST(MavlinkParser, SignedFramesAreDeliveredWithTheSignatureSkipped) {
    Encoder e(1, 1);
    Bytes signed_frame = heartbeat_frame(e, 9);
    signed_frame[2] = kIncompatSigned;
    // The incompatibility flags are covered by the checksum: recompute it.
    const auto* info = find_message(Heartbeat::kId);
    Crc16 crc;
    crc.add(std::span<const std::uint8_t>(signed_frame.data() + 1, signed_frame.size() - 3));
    crc.add(info->crc_extra);
    wire::put(signed_frame.data() + signed_frame.size() - 2, crc.value());
    for (int i = 0; i < 13; ++i) {
        signed_frame.push_back(static_cast<std::uint8_t>(0xFD - i));  // signature bytes that look like magic
    }
    const auto c = run(concat({signed_frame, heartbeat_frame(e, 10)}));
    ASSERT_EQ(c.frames.size(), 2u);
    EXPECT_TRUE(c.frames[0].is_signed);
    EXPECT_EQ(decode<Heartbeat>(c.frames[0])->custom_mode, 9u);
    EXPECT_FALSE(c.frames[1].is_signed);
    EXPECT_EQ(c.stats.signed_frames, 1u);
    EXPECT_EQ(c.stats.garbage_bytes, 0u);
}

TEST(MavlinkParser, UnknownMessageIdsAreDeliveredUnverifiedWhenFollowedByAFrame) {
    Encoder e(1, 1);
    const auto c =
        run(concat({unknown_frame(12345, {1, 2, 3}), heartbeat_frame(e), unknown_frame(4000, {9})}));
    ASSERT_EQ(c.frames.size(), 3u);
    EXPECT_EQ(c.frames[0].msgid, 12345u);
    EXPECT_FALSE(c.frames[0].checksum_verified);
    EXPECT_EQ(c.frames[0].payload_length, 3);
    EXPECT_EQ(c.frames[0].payload[2], 3);
    EXPECT_TRUE(c.frames[1].checksum_verified);
    EXPECT_EQ(c.frames[2].msgid, 4000u);  // the last one ends with the stream
    EXPECT_EQ(c.stats.unknown_msgid, 2u);
    EXPECT_EQ(c.stats.frames_ok, 1u);
}

TEST(MavlinkParser, StrayStartByteInNoiseDoesNotSwallowFrames) {
    // 0xFD followed by bytes that read as an unknown message id; the real frame starts inside its span.
    Encoder e(1, 1);
    const Bytes noise{0xFD, 0x05, 0x00, 0x00, 0x00, 0x01, 0x01, 0x39, 0x30, 0x00};
    const auto c = run(concat({noise, heartbeat_frame(e, 5)}));
    ASSERT_EQ(c.frames.size(), 1u);
    EXPECT_EQ(decode<Heartbeat>(c.frames[0])->custom_mode, 5u);
    EXPECT_EQ(c.stats.unknown_msgid, 0u);
}

// A stray start byte in damaged bytes reads as a MAVLink 1 frame of an undeclared id whose claimed end falls
// on a 0xFD inside the next, good frame (here its sequence number), so the look-ahead rule took it for a
// frame followed by another: it was delivered unverified and the verified frame it overlaps was lost. Found
// by comparing with the C library's parser on an ArduPilot-like stream (reference_compare_test.cpp: a
// damaged AHRS2 frame whose payload held 0xFE and an undeclared id). A candidate that cannot be verified
// now waits for every candidate with a known id that starts inside it, and loses to a verified one.
TEST(MavlinkParser, UnverifiableCandidateEndingOnAStartByteInsideAVerifiedFrameDoesNotSwallowIt) {
    const Bytes good = heartbeat_with_seq(0xFD, 7);
    // 0xFE, length 5, seq, sysid, compid, message id 103 (undeclared), 3 more bytes: it claims 6 + 5 + 2 = 13
    // bytes, 4 of them in the good frame, and the byte after its claimed end is the good frame's 0xFD.
    const Bytes stray{kMagicV1, 5, 0x4B, 0x71, 0x1F, 103, 0x8B, 0xD9, 0xCA};
    const Bytes stream = concat({stray, good, heartbeat_with_seq(0xFE, 8)});
    for (std::size_t chunk = 0; chunk <= 97; ++chunk) {
        const auto c = run(stream, chunk);
        EXPECT_EQ(heartbeats(c), (std::vector<std::uint32_t>{7, 8})) << chunk;
        EXPECT_EQ(c.stats.unknown_msgid, 0u) << chunk;
        EXPECT_EQ(c.stats.frames_ok, 2u) << chunk;
        EXPECT_EQ(c.stats.truncated, 1u) << chunk;  // the stray's claimed stretch, cut by the good frame
        EXPECT_EQ(c.stats.garbage_bytes, 0u) << chunk;
    }
}

// The same with a real frame of an undeclared message whose length byte was damaged (5 became 9): its
// claimed end lies 4 bytes into the good frame after it, on that frame's 0xFD.
TEST(MavlinkParser, UndeclaredFrameWithADamagedLengthDoesNotSwallowTheVerifiedFrameAfterIt) {
    Bytes unknown = unknown_frame(12345, {1, 2, 3, 4, 5});
    unknown[1] = 9;
    const Bytes stream = concat({unknown, heartbeat_with_seq(0xFD, 7), heartbeat_with_seq(0xFE, 8)});
    for (std::size_t chunk = 0; chunk <= 97; ++chunk) {
        const auto c = run(stream, chunk);
        EXPECT_EQ(heartbeats(c), (std::vector<std::uint32_t>{7, 8})) << chunk;
        EXPECT_EQ(c.frames.size(), 2u) << chunk;
        EXPECT_EQ(c.stats.unknown_msgid, 0u) << chunk;
        EXPECT_EQ(c.stats.truncated, 1u) << chunk;
        EXPECT_EQ(c.stats.bad_checksum, 0u) << chunk;
        EXPECT_EQ(c.stats.garbage_bytes, 0u) << chunk;
    }
}

// Bytes as received in the comparison with the C library (seed 137): a MISSION_CURRENT whose
// incompatibility flags were hit (0x00 became 0x40), then an intact GPS_RAW_INT. The damaged frame's own
// sequence number, 0xFD, reads as a signed frame of an undeclared id claiming 26 bytes, whose end falls on
// the GPS frame's sequence number 0xFE. The C library gives the damaged frame up at its flag byte and decodes
// the GPS frame; airseg lost it to the unverifiable candidate.
TEST(MavlinkParser, SignedUnverifiableCandidateFromADamagedFrameDoesNotSwallowTheNextFrame) {
    const Bytes damaged{0xFD, 0x0E, 0x40, 0x00, 0xFD, 0x01, 0x01, 0x2A, 0x00, 0x00, 0x6C, 0x00, 0xF7,
                        0x11, 0x00, 0x00, 0x42, 0xB5, 0xAC, 0xE7, 0xA6, 0x0F, 0xE2, 0xC5, 0xC8, 0x0B};
    const Bytes gps{0xFD, 0x33, 0x00, 0x00, 0xFE, 0x01, 0x01, 0x18, 0x00, 0x00, 0x30, 0x00, 0x00,
                    0x00, 0x00, 0x00, 0x00, 0x00, 0xDD, 0x04, 0xA8, 0x40, 0x00, 0x00, 0x00, 0x00,
                    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x3B, 0x00, 0x08, 0x00, 0x62, 0x00, 0x00,
                    0xFC, 0xA2, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x96, 0x7B, 0x12, 0x1A,
                    0xB5, 0xEE, 0x79, 0x2D, 0x00, 0x00, 0x00, 0x00, 0xC0, 0xC6, 0x5E};
    const Bytes stream = concat({damaged, gps});
    for (std::size_t chunk = 0; chunk <= 97; ++chunk) {
        const auto c = run(stream, chunk);
        ASSERT_EQ(c.frames.size(), 1u) << chunk;
        EXPECT_EQ(c.frames[0].msgid, GpsRawInt::kId) << chunk;
        EXPECT_EQ(c.frames[0].seq, 0xFE) << chunk;
        EXPECT_EQ(c.stats.unknown_msgid, 0u) << chunk;
    }
}

// Intact bytes from the comparison with the C library (seed 2, 50 MB): an AHRS2 (undeclared) whose payload
// holds 0xFE 0x1C ...: a MAVLink 1 HEARTBEAT claiming 28 bytes, reaching into the SYS_STATUS after it, whose
// checksum matches there by chance (one in 65,536). Waiting for candidates inside undeclared frames made
// that coincidence deliver a HEARTBEAT that was never sent, and lose both real frames. A frame inside another
// must have a length its message can have (a MAVLink 1 HEARTBEAT has 9 bytes).
TEST(MavlinkParser, ChecksumMatchingByChanceInsideAnUndeclaredFrameDoesNotWin) {
    const Bytes ahrs2{0xFD, 0x18, 0x00, 0x00, 0xCB, 0x01, 0x01, 0xB2, 0x00, 0x00, 0xE0, 0x09,
                      0x18, 0x4B, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xFE, 0x1C,
                      0xDB, 0xD9, 0x00, 0x00, 0x00, 0x00, 0xC2, 0xF5, 0x60, 0x41, 0x3E, 0xF9};
    const Bytes sys_status{0xFD, 0x28, 0x00, 0x00, 0xCC, 0x01, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00,
                           0x00, 0x00, 0x00, 0x00, 0x00, 0x0A, 0xC2, 0x62, 0xBC, 0x8A, 0x27, 0x00, 0x00,
                           0x95, 0x00, 0x3E, 0x00, 0x0F, 0x00, 0x2B, 0x3D, 0x31, 0x55, 0x3F, 0x00, 0x00,
                           0x00, 0xBE, 0x3D, 0x00, 0x00, 0x00, 0x0A, 0x00, 0x00, 0x00, 0x64, 0xE4, 0x62};
    const Bytes stream = concat({ahrs2, sys_status});
    for (std::size_t chunk = 0; chunk <= 97; ++chunk) {
        const auto c = run(stream, chunk);
        ASSERT_EQ(c.frames.size(), 2u) << chunk;
        EXPECT_EQ(c.frames[0].msgid, 178u) << chunk;
        EXPECT_TRUE(c.frames[0].checksum_verified) << chunk;  // AHRS2 is in the dialect table: verified too
        EXPECT_FALSE(c.frames[0].typed) << chunk;
        EXPECT_EQ(c.frames[1].msgid, SysStatus::kId) << chunk;
        EXPECT_TRUE(c.frames[1].checksum_verified) << chunk;
        EXPECT_EQ(c.stats.garbage_bytes, 0u) << chunk;
    }
}

// A signed frame whose signature lost a byte on the line: its checksum still matches, and the start byte of
// the next frame was taken as the signature's last byte, losing that frame (the C library loses it too).
// The signature is not verified, so a verified frame that starts inside it now wins over it.
TEST(MavlinkParser, SignatureThatLostAByteDoesNotSwallowTheNextFrame) {
    Encoder e(1, 1);
    Bytes signed_frame = heartbeat_frame(e, 9);
    signed_frame[2] = kIncompatSigned;
    const auto* info = find_message(Heartbeat::kId);
    Crc16 crc;
    crc.add(std::span<const std::uint8_t>(signed_frame.data() + 1, signed_frame.size() - 3));
    crc.add(info->crc_extra);
    wire::put(signed_frame.data() + signed_frame.size() - 2, crc.value());
    for (int i = 0; i < 12; ++i) {  // one signature byte short
        signed_frame.push_back(static_cast<std::uint8_t>(0x30 + i));
    }
    const Bytes stream = concat({signed_frame, heartbeat_frame(e, 10), heartbeat_frame(e, 11)});
    for (std::size_t chunk = 0; chunk <= 97; ++chunk) {
        const auto c = run(stream, chunk);
        EXPECT_EQ(heartbeats(c), (std::vector<std::uint32_t>{9, 10, 11})) << chunk;
        ASSERT_EQ(c.frames.size(), 3u) << chunk;
        EXPECT_TRUE(c.frames[0].is_signed) << chunk;
        EXPECT_EQ(c.stats.signed_frames, 1u) << chunk;
        EXPECT_EQ(c.stats.garbage_bytes, 0u) << chunk;
    }
    // One byte too many in the signature: that byte is noise, nothing is lost.
    Bytes long_signature = signed_frame;
    long_signature.insert(long_signature.end(), {0x3C, 0x3D});
    const auto c = run(concat({long_signature, heartbeat_frame(e, 12)}));
    EXPECT_EQ(heartbeats(c), (std::vector<std::uint32_t>{9, 12}));
    EXPECT_EQ(c.stats.garbage_bytes, 1u);
}

// A start byte whose header has an undeclared id and an unknown incompatibility flag can be neither verified
// nor delivered (the C library gives it up at the flag byte). It used to take the bytes its length claims
// when a start byte followed them, and an undeclared frame that begins inside it was lost; it is now given
// up at its header.
TEST(MavlinkParser, UndeclaredIdWithUnknownIncompatibilityFlagIsGivenUpAtItsHeader) {
    Encoder e(1, 1);
    const Bytes unknown = unknown_frame(4000, {1, 2, 3});
    // Claims 10 + 13 + 2 = 25 bytes: itself and the whole undeclared frame after it.
    const Bytes stray{kMagicV2, 13, 0x04, 0x00, 0x00, 0x01, 0x01, 0x39, 0x30, 0x00};
    const Bytes stream = concat({stray, unknown, heartbeat_frame(e, 3)});
    for (std::size_t chunk = 0; chunk <= 97; ++chunk) {
        const auto c = run(stream, chunk);
        ASSERT_EQ(c.frames.size(), 2u) << chunk;
        EXPECT_EQ(c.frames[0].msgid, 4000u) << chunk;
        EXPECT_FALSE(c.frames[0].checksum_verified) << chunk;
        EXPECT_EQ(heartbeats(c), (std::vector<std::uint32_t>{3})) << chunk;
        EXPECT_EQ(c.stats.incompat_rejected, 0u) << chunk;
        EXPECT_EQ(c.stats.unknown_msgid, 1u) << chunk;
    }
}

// An undeclared frame holding a start byte that reads as a declared message (a MAVLink 1 AUTOPILOT_VERSION,
// 68 bytes) must wait until that candidate can be judged, or until a verified frame after it is complete (the
// candidate can then no longer be complete first). So the frame after it is not held back on a quiet line.
TEST(MavlinkParser, UndeclaredFrameWaitingForACandidateInsideItDoesNotHoldBackTheFrameAfterIt) {
    Encoder e(1, 1);
    const Bytes unknown =
        unknown_frame(12345, {0x00, kMagicV1, 60, 0x00, 0x01, 0x01, AutopilotVersion::kId, 0x00});
    const Bytes stream = concat({unknown, heartbeat_frame(e, 5)});
    for (std::size_t chunk = 1; chunk <= stream.size(); ++chunk) {
        Parser parser;
        std::vector<Frame> frames;
        auto sink = [&](const Frame& f) { frames.push_back(f); };
        for (std::size_t i = 0; i < stream.size(); i += chunk) {
            parser.push(std::span(stream).subspan(i, std::min(chunk, stream.size() - i)), sink);
        }
        ASSERT_EQ(frames.size(), 2u) << chunk;  // no finish(): the line is quiet
        EXPECT_EQ(frames[0].msgid, 12345u) << chunk;
        EXPECT_EQ(decode<Heartbeat>(frames[1])->custom_mode, 5u) << chunk;
    }
    // Followed by another undeclared frame only, it waits for the candidate (or the end of the stream).
    Parser parser;
    std::vector<Frame> frames;
    auto sink = [&](const Frame& f) { frames.push_back(f); };
    parser.push(concat({unknown, unknown_frame(4000, {9})}), sink);
    EXPECT_TRUE(frames.empty());
    parser.finish(sink);
    ASSERT_EQ(frames.size(), 2u);
    EXPECT_EQ(frames[0].msgid, 12345u);
    EXPECT_EQ(frames[1].msgid, 4000u);
}

TEST(MavlinkParser, SequenceGapsCountLostFramesPerSender) {
    Encoder a(1, 1);
    Encoder b(2, 1);
    std::array<std::uint8_t, kMaxFrameLength> scratch{};
    Bytes stream;
    for (int i = 0; i < 10; ++i) {
        const Bytes fa = heartbeat_frame(a);
        if (i != 3 && i != 4) {  // two of a's frames are lost
            stream.insert(stream.end(), fa.begin(), fa.end());
        }
        const Bytes fb = heartbeat_frame(b);
        stream.insert(stream.end(), fb.begin(), fb.end());
    }
    b.encode(Heartbeat{}, scratch);  // one of b's frames never sent: lost
    const Bytes fb = heartbeat_frame(b);
    stream.insert(stream.end(), fb.begin(), fb.end());

    Parser parser;
    parser.push(stream, [](const Frame&) {});
    EXPECT_EQ(parser.stats().seq_lost, 3u);
    ASSERT_NE(parser.link(1, 1), nullptr);
    EXPECT_EQ(parser.link(1, 1)->lost, 2u);
    EXPECT_EQ(parser.link(1, 1)->received, 8u);
    EXPECT_EQ(parser.link(2, 1)->lost, 1u);
    EXPECT_EQ(parser.link(2, 1)->last_seq, 11);
    EXPECT_EQ(parser.link(3, 1), nullptr);
    EXPECT_EQ(parser.links().size(), 2u);
}

TEST(MavlinkParser, AcceptsConstAndMoveOnlyCallables) {
    Encoder e(1, 1);
    const Bytes frame = heartbeat_frame(e, 4);
    Parser parser;
    int seen = 0;
    const auto counter = [&seen](const Frame&) { ++seen; };
    parser.push(frame, counter);
    auto owner = std::make_unique<int>(0);
    parser.push(frame, [&seen, o = std::move(owner)](const Frame&) { seen += 1 + *o; });
    EXPECT_EQ(seen, 2);
}

TEST(MavlinkParser, SequenceWrapIsNotALoss) {
    Encoder e(1, 1);
    Parser parser;
    for (int i = 0; i < 600; ++i) {
        parser.push(heartbeat_frame(e), [](const Frame&) {});
    }
    EXPECT_EQ(parser.stats().seq_lost, 0u);
    EXPECT_EQ(parser.stats().frames_ok, 600u);
}

TEST(MavlinkParser, ForgetsTheLeastRecentlyHeardSenderWhenFull) {
    Parser parser;
    std::vector<Encoder> senders;
    for (std::size_t i = 0; i <= Parser::kMaxLinks; ++i) {
        Encoder e(static_cast<std::uint8_t>(i + 1), 1);
        parser.push(heartbeat_frame(e), [](const Frame&) {});
    }
    EXPECT_EQ(parser.links().size(), Parser::kMaxLinks);
    EXPECT_EQ(parser.link(1, 1), nullptr);
    EXPECT_NE(parser.link(static_cast<std::uint8_t>(Parser::kMaxLinks + 1), 1), nullptr);
}

TEST(MavlinkParser, RandomCorruptionNeverLosesMoreThanTheDamagedFrames) {
    // Seeded: flip one byte in some frames; every undamaged frame must still come out, in order.
    Encoder e(1, 1);
    std::mt19937 rng(7);
    Bytes stream;
    std::vector<std::uint32_t> expected;
    for (std::uint32_t i = 0; i < 300; ++i) {
        Bytes f = heartbeat_frame(e, i);
        if (rng() % 5 == 0) {
            f[rng() % f.size()] ^= static_cast<std::uint8_t>(1 + rng() % 255);
        } else {
            expected.push_back(i);
        }
        stream.insert(stream.end(), f.begin(), f.end());
    }
    const auto c = run(stream, 17);
    std::vector<std::uint32_t> got;
    for (const Frame& f : c.frames) {
        if (auto hb = decode<Heartbeat>(f)) {
            got.push_back(hb->custom_mode);
        }
    }
    // A damaged frame can only disappear; a corrupted custom_mode that still passed the checksum is
    // practically impossible with a 16-bit CRC on one changed byte.
    EXPECT_EQ(got, expected);
}

}  // namespace
}  // namespace airseg::mavlink
