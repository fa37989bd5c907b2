// Fuzzes the MAVLink parser with arbitrary byte streams and checks what must hold for any input:
//  - feeding the stream in chunks (their size derived from the input's length, so that every input byte is
//    stream and seeds are plain captures) gives exactly the frames and the
//    counters of feeding it whole;
//  - every delivered frame is consistent (lengths, verification only for known ids) and, re-encoded from its
//    own header and payload, parses back to the same frame;
//  - the generic field readers and the JSON printer of airseg-mavdump handle every delivered frame.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/fuzz/require.hpp"
#include "tools/mavdump/frame_json.hpp"

namespace {

using namespace airseg::mavlink;

bool same_frame(const Frame& a, const Frame& b) {
    return a.version == b.version && a.incompat_flags == b.incompat_flags &&
           a.compat_flags == b.compat_flags && a.seq == b.seq && a.sysid == b.sysid && a.compid == b.compid &&
           a.msgid == b.msgid && a.wire_length == b.wire_length && a.payload_length == b.payload_length &&
           a.is_signed == b.is_signed && a.checksum_verified == b.checksum_verified && a.payload == b.payload;
}

bool same_stats(const ParserStats& a, const ParserStats& b) {
    return a.frames_ok == b.frames_ok && a.garbage_bytes == b.garbage_bytes &&
           a.bad_checksum == b.bad_checksum && a.truncated == b.truncated &&
           a.unknown_msgid == b.unknown_msgid && a.incompat_rejected == b.incompat_rejected &&
           a.signed_frames == b.signed_frames && a.seq_lost == b.seq_lost;
}

void check_frame(const Frame& f) {
    require(f.payload_length >= f.wire_length);
    const MessageInfo* info = find_dialect_message(f.msgid);
    require(f.checksum_verified == (info != nullptr));
    require(f.typed == (find_message(f.msgid) != nullptr && f.checksum_verified));
    require(info == nullptr || f.payload_length >= info->length);
    require((f.incompat_flags & ~kIncompatSigned) == 0);
    require(f.is_signed == ((f.incompat_flags & kIncompatSigned) != 0));
    for (std::size_t i = f.wire_length; i < f.payload.size(); ++i) {
        require(f.payload[i] == 0);
    }
    const std::string json = airseg::mavdump::frame_to_json(f);
    require(!json.empty() && json.front() == '{' && json.back() == '}');

    if (info != nullptr && !f.is_signed) {
        std::array<std::uint8_t, kMaxFrameLength> out{};
        const FrameHeader h{f.version, f.seq, f.sysid, f.compid, f.msgid, f.compat_flags};
        const std::size_t n =
            encode_frame(h, info->crc_extra, std::span(f.payload).first(f.wire_length), out);
        require(n > 0);
        Parser again;
        int count = 0;
        auto same = [&](const Frame& g) {
            ++count;
            require(same_frame(f, g));
        };
        again.push(std::span(out).first(n), same);
        again.finish(same);
        require(count == 1);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::size_t chunk = 1 + size % 97;
    const std::span<const std::uint8_t> stream(data, size);

    std::vector<Frame> whole;
    Parser a;
    auto keep = [&](const Frame& f) {
        check_frame(f);
        whole.push_back(f);
    };
    a.push(stream, keep);
    a.finish(keep);

    std::vector<Frame> chunked;
    Parser b;
    auto keep_chunked = [&](const Frame& f) { chunked.push_back(f); };
    for (std::size_t i = 0; i < stream.size(); i += chunk) {
        b.push(stream.subspan(i, std::min(chunk, stream.size() - i)), keep_chunked);
    }
    b.finish(keep_chunked);

    require(whole.size() == chunked.size());
    for (std::size_t i = 0; i < whole.size(); ++i) {
        require(same_frame(whole[i], chunked[i]));
    }
    if (!same_stats(a.stats(), b.stats())) {
        const auto print = [](const char* name, const ParserStats& s) {
            std::fprintf(stderr,
                         "%s: frames_ok %llu garbage %llu bad_checksum %llu truncated %llu unknown %llu "
                         "incompat %llu signed %llu seq_lost %llu\n",
                         name, static_cast<unsigned long long>(s.frames_ok),
                         static_cast<unsigned long long>(s.garbage_bytes),
                         static_cast<unsigned long long>(s.bad_checksum),
                         static_cast<unsigned long long>(s.truncated),
                         static_cast<unsigned long long>(s.unknown_msgid),
                         static_cast<unsigned long long>(s.incompat_rejected),
                         static_cast<unsigned long long>(s.signed_frames),
                         static_cast<unsigned long long>(s.seq_lost));
        };
        print("whole", a.stats());
        print("chunked", b.stats());
        require(false);
    }
    require(a.stats().garbage_bytes <= stream.size());
    return 0;
}
