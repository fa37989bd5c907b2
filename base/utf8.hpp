#pragma once
// UTF-8 for text that comes from outside (files, the radio, the autopilot): checked where it enters, and made
// safe to print where it is merely shown. nlohmann::json's dump throws (type_error.316) on malformed UTF-8,
// so text that reaches a JSON document must either have passed valid_utf8() or be dumped with the replace
// handler.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace airseg {

/// Decodes the code point at `text[i]` and moves `i` past it; nullopt (and `i` unchanged) when the bytes
/// there are not well-formed UTF-8: a stray continuation byte, a truncated or overlong sequence, a surrogate
/// (U+D800-U+DFFF), or a value above U+10FFFF (RFC 3629).
inline std::optional<char32_t> utf8_next(std::string_view text, std::size_t& i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
        ++i;
        return c;
    }
    const std::size_t length = c >= 0xf0 ? 4 : c >= 0xe0 ? 3 : c >= 0xc0 ? 2 : 0;
    if (length == 0 || c > 0xf4 || c < 0xc2 || i + length > text.size()) {
        return std::nullopt;
    }
    std::uint32_t code = c & (0x7fu >> length);
    for (std::size_t k = 1; k < length; ++k) {
        const auto next = static_cast<unsigned char>(text[i + k]);
        if ((next & 0xc0) != 0x80) {
            return std::nullopt;
        }
        code = (code << 6) | (next & 0x3fu);
    }
    constexpr std::uint32_t kLeast[] = {0, 0, 0x80, 0x800, 0x10000};
    if (code < kLeast[length] || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) {
        return std::nullopt;
    }
    i += length;
    return static_cast<char32_t>(code);
}

/// The offset of the first byte that is not well-formed UTF-8, or nullopt when the whole text is.
inline std::optional<std::size_t> first_invalid_utf8(std::string_view text) {
    for (std::size_t i = 0; i < text.size();) {
        if (!utf8_next(text, i)) {
            return i;
        }
    }
    return std::nullopt;
}

inline bool valid_utf8(std::string_view text) {
    return !first_invalid_utf8(text).has_value();
}

/// A C0 control character (U+0000-U+001F) or DEL.
inline bool is_control(char32_t c) {
    return c < 0x20 || c == 0x7f;
}

/// The first byte of a text file (a plan, a configuration) that makes it unfit to parse: not UTF-8, or a
/// control character other than tab, line feed and carriage return (yaml-cpp ends a document at a NUL and
/// passes malformed bytes into its strings).
struct TextFault {
    std::size_t offset = 0;
    unsigned char byte = 0;
    bool control = false;  // a control character; else not UTF-8
    /// "not valid UTF-8 (byte 0xff)", "a control character (0x00)".
    std::string what() const {
        constexpr char kHex[] = "0123456789abcdef";
        const std::string hex{'0', 'x', kHex[byte >> 4], kHex[byte & 0xf]};
        return control ? "a control character (" + hex + ")" : "not valid UTF-8 (byte " + hex + ")";
    }
};
inline std::optional<TextFault> first_text_fault(std::string_view text) {
    for (std::size_t i = 0; i < text.size();) {
        const std::size_t at = i;
        const auto c = utf8_next(text, i);
        if (!c || (is_control(*c) && *c != '\t' && *c != '\n' && *c != '\r')) {
            return TextFault{at, static_cast<unsigned char>(text[at]), c.has_value()};
        }
    }
    return std::nullopt;
}

/// Line and column (both from 1, the column in bytes) of `offset` in `text`, for "file:line:column" messages.
struct TextPosition {
    std::size_t line = 1;
    std::size_t column = 1;
};
inline TextPosition position_of(std::string_view text, std::size_t offset) {
    TextPosition p;
    for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++p.line;
            p.column = 1;
        } else {
            ++p.column;
        }
    }
    return p;
}

/// Text from outside as it may appear in a message: malformed bytes and control characters written as \xNN
/// (so a message is always valid UTF-8 and one line), and cut after `max_chars` characters with "…" and the
/// whole length, so a 10 MB value is not echoed whole.
inline std::string excerpt(std::string_view text, std::size_t max_chars = 80) {
    constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    std::size_t chars = 0;
    std::size_t i = 0;
    while (i < text.size()) {
        if (chars == max_chars) {
            out += "… (" + std::to_string(text.size()) + " bytes)";
            return out;
        }
        const std::size_t at = i;
        const auto c = utf8_next(text, i);
        if (!c || is_control(*c)) {
            const auto byte = static_cast<unsigned char>(text[at]);
            out += "\\x";
            out += kHex[byte >> 4];
            out += kHex[byte & 0xf];
            i = at + 1;
        } else {
            out.append(text.substr(at, i - at));
        }
        ++chars;
    }
    return out;
}

}  // namespace airseg
