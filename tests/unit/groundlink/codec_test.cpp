// Byte-level pieces: CRC-32, COBS and resynchronization, frame layout, MAC, replay window.
#include <gtest/gtest.h>

#include <random>
#include <string_view>

#include "services/groundlink/transport/cobs.hpp"
#include "services/groundlink/transport/crc32.hpp"
#include "services/groundlink/transport/frame.hpp"
#include "services/groundlink/transport/frame_mac.hpp"
#include "services/groundlink/transport/replay_window.hpp"

namespace airseg::groundlink {
namespace {

std::vector<std::uint8_t> bytes(std::string_view s) {
    return {s.begin(), s.end()};
}

TEST(GroundlinkCrc32, KnownVectors) {
    EXPECT_EQ(crc32(bytes("123456789")), 0xCBF43926U);
    EXPECT_EQ(crc32(bytes("")), 0x00000000U);
    EXPECT_EQ(crc32(bytes("a")), 0xE8B7BE43U);
    EXPECT_EQ(crc32(bytes("The quick brown fox jumps over the lazy dog")), 0x414FA339U);
    Crc32 split;
    split.update(bytes("12345"));
    split.update(bytes("6789"));
    EXPECT_EQ(split.value(), 0xCBF43926U);
}

// The table-driven CRC reads eight bytes a step: every length and alignment must match the bitwise
// definition.
TEST(GroundlinkCrc32, MatchesTheBitwiseDefinitionAtEveryLengthAndSplit) {
    std::mt19937 rng(3);
    std::vector<std::uint8_t> data(300);
    for (auto& b : data) {
        b = static_cast<std::uint8_t>(rng());
    }
    auto bitwise = [](std::span<const std::uint8_t> d) {
        std::uint32_t c = 0xFFFFFFFFU;
        for (std::uint8_t b : d) {
            c ^= b;
            for (int k = 0; k < 8; ++k) {
                c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1) : c >> 1;
            }
        }
        return ~c;
    };
    for (std::size_t n = 0; n <= data.size(); n += (n < 40 ? 1 : 37)) {
        const std::span<const std::uint8_t> d(data.data(), n);
        ASSERT_EQ(crc32(d), bitwise(d)) << n;
        Crc32 split;
        split.update(d.first(n / 3));
        split.update(d.subspan(n / 3));
        ASSERT_EQ(split.value(), bitwise(d)) << n;
    }
}

// The run-at-a-time encoder against the byte-at-a-time definition, around zeros and 254-byte runs.
TEST(GroundlinkCobs, EncodingMatchesTheByteAtATimeDefinition) {
    auto reference = [](std::span<const std::uint8_t> data) {
        std::vector<std::uint8_t> out{0};
        std::size_t code_pos = 0;
        std::uint8_t code = 1;
        for (std::uint8_t b : data) {
            if (b != 0) {
                out.push_back(b);
                ++code;
            }
            if (b == 0 || code == 0xFF) {
                out[code_pos] = code;
                code_pos = out.size();
                out.push_back(0);
                code = 1;
            }
        }
        out[code_pos] = code;
        out.push_back(0);
        return out;
    };
    std::mt19937 rng(11);
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<std::uint8_t> in(rng() % 700);
        const unsigned zero_every = 1 + rng() % 400;
        for (auto& b : in) {
            b = static_cast<std::uint8_t>(rng() % zero_every == 0 ? 0 : 1 + rng() % 255);
        }
        std::vector<std::uint8_t> out{0xAB};  // appends after what is there
        cobs_encode(in, out);
        ASSERT_EQ(std::vector<std::uint8_t>(out.begin() + 1, out.end()), reference(in)) << trial;
        const auto back = cobs_decode(std::span(out).subspan(1, out.size() - 2));
        ASSERT_TRUE(back.has_value());
        ASSERT_EQ(*back, in);
    }
}

TEST(GroundlinkCobs, KnownVectors) {
    auto enc = [](std::vector<std::uint8_t> in) {
        std::vector<std::uint8_t> out;
        cobs_encode(in, out);
        return out;
    };
    EXPECT_EQ(enc({0x00}), (std::vector<std::uint8_t>{0x01, 0x01, 0x00}));
    EXPECT_EQ(enc({0x00, 0x00}), (std::vector<std::uint8_t>{0x01, 0x01, 0x01, 0x00}));
    EXPECT_EQ(enc({0x11, 0x22, 0x00, 0x33}), (std::vector<std::uint8_t>{0x03, 0x11, 0x22, 0x02, 0x33, 0x00}));
    EXPECT_EQ(enc({0x11, 0x00, 0x00, 0x00}), (std::vector<std::uint8_t>{0x02, 0x11, 0x01, 0x01, 0x01, 0x00}));
    std::vector<std::uint8_t> run(254);
    for (std::size_t i = 0; i < run.size(); ++i) {
        run[i] = static_cast<std::uint8_t>(i + 1);
    }
    const auto e = enc(run);
    ASSERT_EQ(e.size(), 256U + 1U);
    EXPECT_EQ(e.front(), 0xFF);
    EXPECT_EQ(e[255], 0x01);
}

TEST(GroundlinkCobs, RoundTripAndWorstCaseOverheadUnderOnePercent) {
    std::mt19937 rng(7);
    for (std::size_t n : {0U, 1U, 253U, 254U, 255U, 508U, 1000U, 4000U}) {
        std::vector<std::uint8_t> in(n);
        for (auto& b : in) {
            b = static_cast<std::uint8_t>(rng() % 4 == 0 ? 0 : rng());
        }
        std::vector<std::uint8_t> out;
        cobs_encode(in, out);
        ASSERT_EQ(out.back(), 0);
        EXPECT_LE(out.size(), cobs_max_encoded(n));
        auto dec = cobs_decode(std::span(out).first(out.size() - 1));
        ASSERT_TRUE(dec.has_value());
        EXPECT_EQ(*dec, in);
        // No zero byte: the worst case for stuffing.
        std::vector<std::uint8_t> nz(n, 0x5A);
        std::vector<std::uint8_t> nz_out;
        cobs_encode(nz, nz_out);
        if (n >= 1000) {
            EXPECT_LE(static_cast<double>(nz_out.size() - 1 - n), 0.01 * static_cast<double>(n));
        }
    }
}

TEST(GroundlinkCobs, RejectsInvalidEncodings) {
    EXPECT_FALSE(cobs_decode(std::vector<std::uint8_t>{0x05, 0x11}).has_value());  // run past the end
    EXPECT_FALSE(cobs_decode(std::vector<std::uint8_t>{0x03, 0x11, 0x00}).has_value());
}

std::vector<std::vector<std::uint8_t>> deframe(const std::vector<std::uint8_t>& stream, int* errors) {
    CobsDeframer d(600);
    std::vector<std::vector<std::uint8_t>> frames;
    d.feed(
        stream, [&](std::vector<std::uint8_t>&& f) { frames.push_back(std::move(f)); }, [&] { ++*errors; });
    return frames;
}

TEST(GroundlinkCobsDeframer, ResynchronizesWithinOneFrameAfterLostInsertedOrCorruptedBytes) {
    std::vector<std::vector<std::uint8_t>> sent;
    for (int i = 0; i < 5; ++i) {
        sent.push_back(std::vector<std::uint8_t>(40, static_cast<std::uint8_t>(i + 1)));
        sent.back()[10] = 0;  // zeros inside the payload
    }
    std::vector<std::vector<std::uint8_t>> enc;
    for (const auto& f : sent) {
        std::vector<std::uint8_t> e;
        cobs_encode(f, e);
        enc.push_back(e);
    }
    auto join = [&](int damaged, auto&& damage) {
        std::vector<std::uint8_t> s;
        for (int i = 0; i < 5; ++i) {
            auto e = enc[static_cast<std::size_t>(i)];
            if (i == damaged) {
                damage(e);
            }
            s.insert(s.end(), e.begin(), e.end());
        }
        return s;
    };
    // A decoded frame that is not byte-identical to a sent one would fail the CRC one layer up; here we check
    // that the frames after the damaged one come through intact.
    for (int kind = 0; kind < 4; ++kind) {
        auto stream = join(2, [kind](std::vector<std::uint8_t>& e) {
            if (kind == 0) {
                e.erase(e.begin() + 5);  // lost byte
            } else if (kind == 1) {
                e.insert(e.begin() + 5, 0x77);  // inserted byte
            } else if (kind == 2) {
                e[5] ^= 0x40;  // corrupted byte
            } else {
                e.pop_back();  // lost delimiter: merges with the next frame
            }
        });
        int errors = 0;
        auto got = deframe(stream, &errors);
        int intact_after = 0;
        for (const auto& f : got) {
            if (f == sent[4] || (kind != 3 && f == sent[3])) {
                ++intact_after;
            }
        }
        EXPECT_EQ(intact_after, kind == 3 ? 1 : 2) << "damage kind " << kind;
        EXPECT_TRUE(std::find(got.begin(), got.end(), sent[0]) != got.end());
        EXPECT_TRUE(std::find(got.begin(), got.end(), sent[1]) != got.end());
    }
}

TEST(GroundlinkCobsDeframer, DiscardsOversizeFramesAndRecovers) {
    std::vector<std::uint8_t> stream(2000, 0x33);  // a run with no delimiter
    stream.push_back(0);
    std::vector<std::uint8_t> good;
    cobs_encode(std::vector<std::uint8_t>{1, 2, 3}, good);
    stream.insert(stream.end(), good.begin(), good.end());
    int errors = 0;
    auto got = deframe(stream, &errors);
    EXPECT_EQ(errors, 1);
    ASSERT_EQ(got.size(), 1U);
    EXPECT_EQ(got[0], (std::vector<std::uint8_t>{1, 2, 3}));
}

TEST(GroundlinkFrameMac, TagDependsOnKeyContextAndBytes) {
    std::array<std::uint8_t, kKeyBytes> k1{};
    std::array<std::uint8_t, kKeyBytes> k2{};
    k2[0] = 1;
    FrameMac m1(k1);
    FrameMac m2(k2);
    const auto data = bytes("frame bytes");
    const MacContext ctx{1, 2, 3};
    const auto t = m1.tag(ctx, data);
    EXPECT_TRUE(m1.verify(ctx, data, t));
    EXPECT_FALSE(m2.verify(ctx, data, t));
    EXPECT_FALSE(m1.verify(MacContext{1, 2, 4}, data, t));  // other frame number
    EXPECT_FALSE(m1.verify(MacContext{2, 1, 3}, data, t));  // other direction / session
    auto flipped = data;
    flipped[0] ^= 1;
    EXPECT_FALSE(m1.verify(ctx, flipped, t));
    EXPECT_GE(t.size() * 8, 48U);
}

TEST(GroundlinkFrame, ChunksRoundTripAndTheLastOmitsItsLength) {
    const std::vector<std::uint8_t> d1{1, 2, 3};
    const std::vector<std::uint8_t> d2{9, 8};
    std::vector<frame::Chunk> chunks;
    chunks.emplace_back(frame::AckChunk{2, 0xFFFE, {0x05}});
    chunks.emplace_back(frame::ReportChunk{321});
    chunks.emplace_back(frame::FastChunk{1, 0x1234, true, 7, 2, 3, d1});
    chunks.emplace_back(frame::SafeChunk{3, true, 0xABCD, d2});
    const auto plain = frame::encode_data(0x2, 0x123456, chunks);
    std::size_t expect = frame::kDataHeaderBytes - 2;  // last chunk saves its 2 length bytes
    for (const auto& c : chunks) {
        expect += frame::encoded_size(c);
    }
    EXPECT_EQ(plain.size(), expect);
    EXPECT_EQ(frame::kind_of(plain), frame::Kind::Data);
    EXPECT_EQ(frame::heard_mask_of(plain), 2);
    EXPECT_EQ(frame::frame_number_of(plain), 0x123456U);
    const auto got = frame::decode_chunks(plain);
    ASSERT_TRUE(got.has_value());
    ASSERT_EQ(got->size(), 4U);
    const auto& a = std::get<frame::AckChunk>((*got)[0]);
    EXPECT_EQ(a.channel, 2);
    EXPECT_EQ(a.next_expected, 0xFFFE);
    EXPECT_EQ(a.bitmap, std::vector<std::uint8_t>{0x05});
    EXPECT_EQ(std::get<frame::ReportChunk>((*got)[1]).byte_error_ppm, 321);
    const auto& f = std::get<frame::FastChunk>((*got)[2]);
    EXPECT_EQ(f.topic, 0x1234);
    EXPECT_EQ(f.index, 2);
    EXPECT_EQ(f.count, 3);
    EXPECT_EQ(std::vector<std::uint8_t>(f.data.begin(), f.data.end()), d1);
    const auto& s = std::get<frame::SafeChunk>((*got)[3]);
    EXPECT_TRUE(s.end);
    EXPECT_EQ(s.seq, 0xABCD);
    EXPECT_EQ(std::vector<std::uint8_t>(s.data.begin(), s.data.end()), d2);
}

TEST(GroundlinkFrame, MalformedChunksAreRejectedNotTrusted) {
    auto plain = frame::encode_data(0, 1, {});
    plain.push_back(0xE0);  // unknown chunk type 7
    EXPECT_FALSE(frame::decode_chunks(plain).has_value());
    auto truncated = frame::encode_data(0, 1, {});
    truncated.push_back(static_cast<std::uint8_t>(1 << 5));  // Safe chunk with no sequence number
    EXPECT_FALSE(frame::decode_chunks(truncated).has_value());
    auto bad_len = frame::encode_data(0, 1, {});
    for (std::uint8_t b :
         {std::uint8_t{1 << 5}, std::uint8_t{0}, std::uint8_t{0}, std::uint8_t{0xFF}, std::uint8_t{0x7F}}) {
        bad_len.push_back(b);  // Safe chunk claiming 32 KiB
    }
    EXPECT_FALSE(frame::decode_chunks(bad_len).has_value());
}

TEST(GroundlinkFrame, SealedFrameChecksCrcAndUnkeyedCrcBindsTheSession) {
    const auto plain = frame::encode_data(1, 5, {});
    const MacContext ctx{11, 22, 5};
    auto sealed = frame::seal(plain, nullptr, ctx);
    auto decoded = cobs_decode(std::span(sealed).first(sealed.size() - 1));
    ASSERT_TRUE(decoded.has_value());
    EXPECT_TRUE(frame::check_crc(*decoded, false, ctx).has_value());
    EXPECT_FALSE(frame::check_crc(*decoded, false, MacContext{11, 23, 5}).has_value());
    (*decoded)[2] ^= 0x10;
    EXPECT_FALSE(frame::check_crc(*decoded, false, ctx).has_value());
}

TEST(GroundlinkReplayWindow, RejectsDuplicatesAndTooOldAndReconstructsAcrossTheWrap) {
    ReplayWindow w;
    EXPECT_EQ(w.check(0), ReplayWindow::Check::Fresh);
    w.accept(0);
    EXPECT_EQ(w.check(0), ReplayWindow::Check::Duplicate);
    w.accept(5);
    EXPECT_EQ(w.check(3), ReplayWindow::Check::Fresh);  // reordered, not yet seen
    w.accept(3);
    EXPECT_EQ(w.check(3), ReplayWindow::Check::Duplicate);
    w.accept(200);
    EXPECT_EQ(w.check(100), ReplayWindow::Check::TooOld);
    EXPECT_EQ(w.check(199), ReplayWindow::Check::Fresh);

    ReplayWindow wrap;
    const std::uint64_t base = (std::uint64_t{1} << 24) - 3;
    wrap.accept(base);
    EXPECT_EQ(wrap.reconstruct(static_cast<std::uint32_t>((base + 5) & 0xFFFFFFU)), base + 5);
    EXPECT_EQ(wrap.reconstruct(static_cast<std::uint32_t>((base - 2) & 0xFFFFFFU)), base - 2);
}

TEST(GroundlinkReplayWindow, SaysHowManyNumbersAFrameSkippedAndWhenOneFillsAGap) {
    ReplayWindow w;
    EXPECT_EQ(w.skipped_by(7), 0);  // the first frame heard: nothing to compare with
    w.accept(7);
    EXPECT_EQ(w.skipped_by(8), 0);
    w.accept(8);
    EXPECT_EQ(w.skipped_by(12), 3);  // 9, 10 and 11 never arrived (yet)
    w.accept(12);
    EXPECT_EQ(w.skipped_by(10), -1);  // one of them did, late
}

}  // namespace
}  // namespace airseg::groundlink
