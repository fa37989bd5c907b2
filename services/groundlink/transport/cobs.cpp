#include "services/groundlink/transport/cobs.hpp"

#include <algorithm>
#include <cstring>

namespace airseg::groundlink {

// Whole runs at a time (memchr finds the next zero, memcpy moves the run): frames are mostly long runs.
void cobs_encode(std::span<const std::uint8_t> data, std::vector<std::uint8_t>& out) {
    const std::size_t base = out.size();
    out.resize(base + cobs_max_encoded(data.size()));
    std::uint8_t* dst = out.data() + base;
    const std::uint8_t* src = data.data();
    const std::uint8_t* const end = src + data.size();
    while (true) {
        const auto limit = std::min<std::size_t>(static_cast<std::size_t>(end - src), 0xFE);
        const auto* zero = limit > 0 ? static_cast<const std::uint8_t*>(std::memchr(src, 0, limit)) : nullptr;
        const std::size_t run = zero != nullptr ? static_cast<std::size_t>(zero - src) : limit;
        *dst++ = static_cast<std::uint8_t>(run + 1);
        if (run > 0) {
            std::memcpy(dst, src, run);
        }
        dst += run;
        src += run;
        if (zero != nullptr) {
            ++src;  // the zero ends this block; another follows, if only an empty one
            continue;
        }
        if (run < 0xFE) {
            break;  // the data ended inside this block
        }
    }
    *dst++ = 0;
    out.resize(static_cast<std::size_t>(dst - out.data()));
}

std::optional<std::vector<std::uint8_t>> cobs_decode(std::span<const std::uint8_t> encoded) {
    std::vector<std::uint8_t> out(encoded.size());  // decoding never grows the data
    std::uint8_t* dst = out.data();
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
        if (run > 0) {
            if (std::memchr(encoded.data() + i, 0, run) != nullptr) {
                return std::nullopt;
            }
            std::memcpy(dst, encoded.data() + i, run);
            dst += run;
        }
        i += run;
        if (code != 0xFF && i < encoded.size()) {
            *dst++ = 0;
        }
    }
    out.resize(static_cast<std::size_t>(dst - out.data()));
    return out;
}

}  // namespace airseg::groundlink
