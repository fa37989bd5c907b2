#include "services/groundlink/transport/frame.hpp"

#include <array>

#include "services/groundlink/transport/byte_io.hpp"
#include "services/groundlink/transport/cobs.hpp"
#include "services/groundlink/transport/crc32.hpp"

namespace airseg::groundlink::frame {
namespace {

// A chunk's type: the top three bits of its type byte.
constexpr std::uint8_t kSafe = 1;
constexpr std::uint8_t kFast = 2;
constexpr std::uint8_t kAck = 3;
constexpr std::uint8_t kReport = 4;
constexpr std::uint8_t kToEnd = 0x01;
constexpr std::uint8_t kFlag1 = 0x02;  // Safe: end of message; Fast: fragmented

std::uint8_t type_byte(std::uint8_t type, std::uint8_t level, std::uint8_t flags) {
    return static_cast<std::uint8_t>((type << 5) | ((level & 0x07U) << 2) | (flags & 0x03U));
}

void encode_chunk(const Chunk& c, bool last, std::vector<std::uint8_t>& out) {
    const std::uint8_t to_end = last ? kToEnd : 0;
    if (const auto* s = std::get_if<SafeChunk>(&c)) {
        out.push_back(
            type_byte(kSafe, s->channel, static_cast<std::uint8_t>((s->end ? kFlag1 : 0) | to_end)));
        wire::put_u16(out, s->seq);
        if (!last) {
            wire::put_u16(out, static_cast<std::uint16_t>(s->data.size()));
        }
        out.insert(out.end(), s->data.begin(), s->data.end());
    } else if (const auto* f = std::get_if<FastChunk>(&c)) {
        out.push_back(
            type_byte(kFast, f->priority, static_cast<std::uint8_t>((f->fragmented ? kFlag1 : 0) | to_end)));
        wire::put_u16(out, f->topic);
        if (f->fragmented) {
            wire::put_u8(out, f->msg_id);
            wire::put_u8(out, f->index);
            wire::put_u8(out, f->count);
        }
        if (!last) {
            wire::put_u16(out, static_cast<std::uint16_t>(f->data.size()));
        }
        out.insert(out.end(), f->data.begin(), f->data.end());
    } else if (const auto* a = std::get_if<AckChunk>(&c)) {
        out.push_back(type_byte(kAck, a->channel, 0));
        wire::put_u16(out, a->next_expected);
        wire::put_u8(out, static_cast<std::uint8_t>(a->bitmap.size()));
        out.insert(out.end(), a->bitmap.begin(), a->bitmap.end());
    } else if (const auto* r = std::get_if<ReportChunk>(&c)) {
        out.push_back(type_byte(kReport, 0, 0));
        wire::put_u16(out, r->byte_error_ppm);
    }
}

// What an unkeyed frame's CRC covers before the frame: both session nonces.
std::array<std::uint8_t, 16> nonce_prefix(const MacContext& ctx) {
    std::array<std::uint8_t, 16> prefix{};
    wire::store_u64(prefix.data(), ctx.sender_nonce);
    wire::store_u64(prefix.data() + 8, ctx.receiver_nonce);
    return prefix;
}

bool read_data(wire::Reader& r, bool to_end, std::span<const std::uint8_t>& data) {
    std::uint16_t len = 0;
    if (to_end) {
        return r.get_bytes(r.remaining(), data);
    }
    return r.get_u16(len) && r.get_bytes(len, data);
}

}  // namespace

std::size_t encoded_size(const Chunk& c) {
    if (const auto* s = std::get_if<SafeChunk>(&c)) {
        return safe_chunk_overhead() + s->data.size();
    }
    if (const auto* f = std::get_if<FastChunk>(&c)) {
        return fast_chunk_overhead(f->fragmented) + f->data.size();
    }
    if (const auto* a = std::get_if<AckChunk>(&c)) {
        return 4 + a->bitmap.size();
    }
    return 3;
}

std::vector<std::uint8_t> encode_data(std::uint8_t header_flags, std::uint32_t frame_number24,
                                      std::span<const Chunk> chunks) {
    std::size_t size = kDataHeaderBytes + kMacTagBytes + kCrcBytes;  // room for seal_plain() too
    for (const auto& c : chunks) {
        size += encoded_size(c);
    }
    std::vector<std::uint8_t> out;
    out.reserve(size);
    out.push_back(
        static_cast<std::uint8_t>((static_cast<std::uint8_t>(Kind::Data) << 6) | (header_flags & 0x07U)));
    wire::put_u24(out, frame_number24 & kFrameNumberMask);
    for (std::size_t i = 0; i < chunks.size(); ++i) {
        const bool last = i + 1 == chunks.size() && (std::holds_alternative<SafeChunk>(chunks[i]) ||
                                                     std::holds_alternative<FastChunk>(chunks[i]));
        encode_chunk(chunks[i], last, out);
    }
    return out;
}

std::vector<std::uint8_t> encode_hello(const Hello& h) {
    std::vector<std::uint8_t> out;
    out.push_back(
        static_cast<std::uint8_t>((static_cast<std::uint8_t>(Kind::Hello) << 6) | (h.heard_mask & 0x03U)));
    wire::put_u8(out, kProtocolVersion);
    wire::put_u64(out, h.sender_nonce);
    wire::put_u64(out, h.echo_nonce);
    wire::put_u8(out, h.established ? 1 : 0);
    return out;
}

std::vector<std::uint8_t> seal(std::vector<std::uint8_t> frame, const FrameMac* mac, const MacContext& ctx) {
    frame = seal_plain(std::move(frame), mac, ctx);
    std::vector<std::uint8_t> out;
    out.reserve(cobs_max_encoded(frame.size()));
    cobs_encode(frame, out);
    return out;
}

std::vector<std::uint8_t> seal_plain(std::vector<std::uint8_t> frame, const FrameMac* mac,
                                     const MacContext& ctx) {
    Crc32 crc;
    if (mac != nullptr) {
        const MacTag tag = mac->tag(ctx, frame);
        frame.insert(frame.end(), tag.begin(), tag.end());
    } else {
        crc.update(nonce_prefix(ctx));
    }
    crc.update(frame);
    wire::put_u32(frame, crc.value());
    return frame;
}

std::optional<std::span<const std::uint8_t>> check_crc(std::span<const std::uint8_t> plain, bool keyed,
                                                       const MacContext& ctx) {
    if (plain.size() < kCrcBytes + 1) {
        return std::nullopt;
    }
    const auto body = plain.first(plain.size() - kCrcBytes);
    Crc32 crc;
    if (!keyed) {
        crc.update(nonce_prefix(ctx));
    }
    crc.update(body);
    std::uint32_t got = 0;
    for (std::size_t i = 0; i < kCrcBytes; ++i) {
        got |= static_cast<std::uint32_t>(plain[body.size() + i]) << (8 * i);
    }
    if (got != crc.value()) {
        return std::nullopt;
    }
    return body;
}

std::optional<Kind> kind_of(std::span<const std::uint8_t> frame) {
    if (frame.empty() || (frame[0] & 0x38U) != 0) {
        return std::nullopt;
    }
    const auto k = static_cast<std::uint8_t>(frame[0] >> 6);
    if (k > static_cast<std::uint8_t>(Kind::Hello)) {
        return std::nullopt;
    }
    return static_cast<Kind>(k);
}

std::uint8_t heard_mask_of(std::span<const std::uint8_t> frame) {
    return frame.empty() ? 0 : static_cast<std::uint8_t>(frame[0] & 0x03U);
}

bool urgent_of(std::span<const std::uint8_t> frame) {
    return !frame.empty() && (frame[0] & kUrgentFlag) != 0;
}

std::optional<Hello> decode_hello(std::span<const std::uint8_t> frame) {
    if (frame.size() != 1 + kHelloBodyBytes || (frame[0] & kUrgentFlag) != 0) {
        return std::nullopt;
    }
    wire::Reader r(frame.subspan(1));
    Hello h;
    std::uint8_t version = 0;
    std::uint8_t flags = 0;
    r.get_u8(version);
    r.get_u64(h.sender_nonce);
    r.get_u64(h.echo_nonce);
    r.get_u8(flags);
    if (!r.ok() || version != kProtocolVersion || (flags & 0xFEU) != 0) {
        return std::nullopt;
    }
    h.heard_mask = heard_mask_of(frame);
    h.established = (flags & 1U) != 0;
    return h;
}

std::optional<std::uint32_t> frame_number_of(std::span<const std::uint8_t> frame) {
    if (frame.size() < kDataHeaderBytes) {
        return std::nullopt;
    }
    return static_cast<std::uint32_t>(frame[1]) | (static_cast<std::uint32_t>(frame[2]) << 8) |
           (static_cast<std::uint32_t>(frame[3]) << 16);
}

std::optional<std::vector<Chunk>> decode_chunks(std::span<const std::uint8_t> frame) {
    if (frame.size() < kDataHeaderBytes) {
        return std::nullopt;
    }
    wire::Reader r(frame.subspan(kDataHeaderBytes));
    std::vector<Chunk> chunks;
    while (r.remaining() > 0) {
        std::uint8_t b = 0;
        r.get_u8(b);
        const auto type = static_cast<std::uint8_t>(b >> 5);
        const auto level = static_cast<std::uint8_t>((b >> 2) & 0x07U);
        const bool to_end = (b & kToEnd) != 0;
        const bool flag1 = (b & kFlag1) != 0;
        switch (type) {
            case kSafe: {
                SafeChunk s;
                s.channel = level;
                s.end = flag1;
                if (!r.get_u16(s.seq) || !read_data(r, to_end, s.data)) {
                    return std::nullopt;
                }
                chunks.emplace_back(s);
                break;
            }
            case kFast: {
                FastChunk f;
                f.priority = level;
                f.fragmented = flag1;
                if (!r.get_u16(f.topic)) {
                    return std::nullopt;
                }
                if (f.fragmented && !(r.get_u8(f.msg_id) && r.get_u8(f.index) && r.get_u8(f.count))) {
                    return std::nullopt;
                }
                if (f.count == 0 || f.index >= f.count || !read_data(r, to_end, f.data)) {
                    return std::nullopt;
                }
                chunks.emplace_back(f);
                break;
            }
            case kAck: {
                AckChunk a;
                a.channel = level;
                std::uint8_t n = 0;
                std::span<const std::uint8_t> bits;
                if ((b & 0x03U) != 0 || !r.get_u16(a.next_expected) || !r.get_u8(n) || n > kMaxBitmapBytes ||
                    !r.get_bytes(n, bits)) {
                    return std::nullopt;
                }
                a.bitmap.assign(bits.begin(), bits.end());
                chunks.emplace_back(std::move(a));
                break;
            }
            case kReport: {
                ReportChunk rep;
                if ((b & 0x1FU) != 0 || !r.get_u16(rep.byte_error_ppm)) {
                    return std::nullopt;
                }
                chunks.emplace_back(rep);
                break;
            }
            default:
                return std::nullopt;
        }
    }
    return chunks;
}

}  // namespace airseg::groundlink::frame
