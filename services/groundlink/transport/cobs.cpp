#include "services/groundlink/transport/cobs.hpp"

namespace airseg::groundlink {

void cobs_encode(std::span<const std::uint8_t> data, std::vector<std::uint8_t>& out) {
    std::size_t code_pos = out.size();
    out.push_back(0);  // placeholder for the first code byte
    std::uint8_t code = 1;
    for (std::uint8_t b : data) {
        if (b == 0) {
            out[code_pos] = code;
            code_pos = out.size();
            out.push_back(0);
            code = 1;
            continue;
        }
        out.push_back(b);
        ++code;
        if (code == 0xFF) {
            out[code_pos] = code;
            code_pos = out.size();
            out.push_back(0);
            code = 1;
        }
    }
    out[code_pos] = code;
    out.push_back(0);
}

std::optional<std::vector<std::uint8_t>> cobs_decode(std::span<const std::uint8_t> encoded) {
    std::vector<std::uint8_t> out;
    out.reserve(encoded.size());
    std::size_t i = 0;
    while (i < encoded.size()) {
        const std::uint8_t code = encoded[i];
        if (code == 0) {
            return std::nullopt;
        }
        ++i;
        const std::size_t run = code - 1U;
        if (run > encoded.size() - i) {
            return std::nullopt;
        }
        for (std::size_t k = 0; k < run; ++k) {
            if (encoded[i + k] == 0) {
                return std::nullopt;
            }
            out.push_back(encoded[i + k]);
        }
        i += run;
        if (code != 0xFF && i < encoded.size()) {
            out.push_back(0);
        }
    }
    return out;
}

}  // namespace airseg::groundlink
