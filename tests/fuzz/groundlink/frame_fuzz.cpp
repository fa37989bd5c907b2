// Fuzzes the ground-link frame layer below the transport state machine: the COBS deframer and decoder and the
// frame parsers. What must hold for any byte stream:
//  - the deframer yields the same frames whether the stream arrives whole or in input-derived pieces;
//  - every decoded frame re-encodes to exactly the bytes it was decoded from (COBS is a bijection);
//  - the header, hello and chunk parsers accept or refuse every frame without reading out of bounds, and
//    every chunk they return lies inside the frame.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <vector>

#include "services/groundlink/transport/cobs.hpp"
#include "services/groundlink/transport/frame.hpp"
#include "tests/fuzz/require.hpp"

namespace {

using namespace airseg::groundlink;

constexpr std::size_t kMaxEncoded = 600;

struct Deframed {
    std::vector<std::vector<std::uint8_t>> frames;
    std::size_t errors = 0;
};

Deframed deframe(std::span<const std::uint8_t> stream, std::size_t piece) {
    CobsDeframer deframer(kMaxEncoded);
    Deframed out;
    for (std::size_t pos = 0; pos < stream.size(); pos += piece) {
        const auto part = stream.subspan(pos, std::min(piece, stream.size() - pos));
        deframer.feed(
            part, [&](std::vector<std::uint8_t>&& f) { out.frames.push_back(std::move(f)); },
            [&] { ++out.errors; });
    }
    return out;
}

void check_frame(std::span<const std::uint8_t> plain) {
    std::vector<std::uint8_t> encoded;
    cobs_encode(plain, encoded);
    require(encoded.size() <= cobs_max_encoded(plain.size()));
    require(!encoded.empty() && encoded.back() == 0);
    const auto again = cobs_decode(std::span(encoded).first(encoded.size() - 1));
    require(again.has_value() && std::equal(again->begin(), again->end(), plain.begin(), plain.end()));

    for (bool keyed : {false, true}) {
        (void)frame::check_crc(plain, keyed, MacContext{});
    }
    (void)frame::kind_of(plain);
    (void)frame::heard_mask_of(plain);
    (void)frame::urgent_of(plain);
    (void)frame::decode_hello(plain);
    (void)frame::frame_number_of(plain);
    if (auto chunks = frame::decode_chunks(plain)) {
        const auto inside = [&](std::span<const std::uint8_t> d) {
            return d.empty() ||
                   (d.data() >= plain.data() && d.data() + d.size() <= plain.data() + plain.size());
        };
        for (const auto& c : *chunks) {
            if (const auto* safe = std::get_if<frame::SafeChunk>(&c)) {
                require(inside(safe->data));
            } else if (const auto* fast = std::get_if<frame::FastChunk>(&c)) {
                require(inside(fast->data));
                require(fast->index < fast->count || !fast->fragmented);
            } else if (const auto* ack = std::get_if<frame::AckChunk>(&c)) {
                require(ack->bitmap.size() <= frame::kMaxBitmapBytes);
            }
        }
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const std::uint8_t> stream(data, size);
    const Deframed whole = deframe(stream, stream.size() + 1);
    const Deframed pieces = deframe(stream, 1 + (size % 13));
    require(whole.frames == pieces.frames && whole.errors == pieces.errors);
    for (const auto& f : whole.frames) {
        require(f.size() < kMaxEncoded);
        check_frame(f);
    }
    // The input itself as one frame body, whatever the deframer made of it.
    check_frame(stream);
    return 0;
}
