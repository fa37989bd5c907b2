#pragma once
// Text from a peer (an autopilot's STATUSTEXT, a parameter name, a ground station's field) made safe to log,
// show and put in JSON: printable ASCII and well-formed UTF-8 pass unchanged; control characters, DEL and
// every byte that is not part of a well-formed UTF-8 sequence (overlong forms, surrogates, code points past
// U+10FFFF, cut-off sequences) become \xNN, and a backslash becomes \\ so the result reads back
// unambiguously. A JSON dump of the result never throws.
#include <cstdint>
#include <string>
#include <string_view>

namespace airseg {

/// Length of the well-formed UTF-8 sequence at the start of `s` (2..4), or 0 when there is none.
inline std::size_t utf8_sequence_length(std::string_view s) {
    if (s.empty()) {
        return 0;
    }
    const auto c = static_cast<unsigned char>(s[0]);
    const std::size_t length = c >= 0xc2 && c <= 0xdf   ? 2
                               : c >= 0xe0 && c <= 0xef ? 3
                               : c >= 0xf0 && c <= 0xf4 ? 4
                                                        : 0;
    if (length == 0 || s.size() < length) {
        return 0;
    }
    std::uint32_t code = c & (0x7fu >> length);
    for (std::size_t k = 1; k < length; ++k) {
        const auto next = static_cast<unsigned char>(s[k]);
        if ((next & 0xc0) != 0x80) {
            return 0;
        }
        code = (code << 6) | (next & 0x3fu);
    }
    constexpr std::uint32_t kLeast[] = {0, 0, 0x80, 0x800, 0x10000};
    if (code < kLeast[length] || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) {
        return 0;
    }
    return length;
}

inline std::string printable(std::string_view raw) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    out.reserve(raw.size());
    std::size_t i = 0;
    while (i < raw.size()) {
        const auto c = static_cast<unsigned char>(raw[i]);
        if (c >= 0x20 && c < 0x7f) {
            if (c == '\\') {
                out += '\\';
            }
            out += static_cast<char>(c);
            ++i;
            continue;
        }
        if (const std::size_t n = c >= 0x80 ? utf8_sequence_length(raw.substr(i)) : 0; n > 0) {
            out.append(raw.substr(i, n));
            i += n;
            continue;
        }
        out += "\\x";
        out += kHex[c >> 4];
        out += kHex[c & 0x0f];
        ++i;
    }
    return out;
}

}  // namespace airseg
