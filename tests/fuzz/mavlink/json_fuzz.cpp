// Fuzzes airseg-mavdump --encode with arbitrary input lines: no crash, and every line it accepts becomes
// exactly one frame that the parser verifies (or, for a raw unknown id, delivers unverified).
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "services/autopilot/mavlink/parser.hpp"
#include "tools/mavdump/frame_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    airseg::mavdump::JsonFrameEncoder encoder;
    const std::string_view line(reinterpret_cast<const char*>(data), size);
    const auto result = encoder.encode_line(line);
    if (!result.error.empty()) {
        if (!result.frame.empty()) {
            std::abort();
        }
        return 0;
    }
    airseg::mavlink::Parser parser;
    int frames = 0;
    auto count = [&](const airseg::mavlink::Frame& f) {
        ++frames;
        // A decoded line must itself be accepted again.
        if (f.checksum_verified && !encoder.encode_line(airseg::mavdump::frame_to_json(f)).error.empty()) {
            std::abort();
        }
    };
    parser.push(result.frame, count);
    parser.finish(count);
    if (frames != 1) {
        std::abort();
    }
    return 0;
}
