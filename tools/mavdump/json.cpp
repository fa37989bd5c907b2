#include "tools/mavdump/json.hpp"

#include <cstdio>

namespace airseg::mavdump {
namespace {

constexpr int kMaxDepth = 32;

class Reader {
  public:
    explicit Reader(std::string_view text) : text_(text) {}

    JsonParseResult run() {
        JsonParseResult r;
        JsonValue v;
        skip_space();
        if (!value(v, 0)) {
            r.error = error_;
            return r;
        }
        skip_space();
        if (pos_ != text_.size()) {
            r.error = at("unexpected text after the JSON value");
            return r;
        }
        r.value = std::move(v);
        return r;
    }

  private:
    std::string at(std::string_view what) const {
        return std::string(what) + " at byte " + std::to_string(pos_);
    }
    bool fail(std::string_view what) {
        if (error_.empty()) {
            error_ = at(what);
        }
        return false;
    }
    void skip_space() {
        while (pos_ < text_.size() &&
               (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\r' || text_[pos_] == '\n')) {
            ++pos_;
        }
    }
    bool literal(std::string_view word) {
        if (text_.substr(pos_, word.size()) != word) {
            return fail("invalid literal");
        }
        pos_ += word.size();
        return true;
    }

    bool value(JsonValue& out, int depth) {
        if (depth > kMaxDepth) {
            return fail("nesting too deep");
        }
        if (pos_ >= text_.size()) {
            return fail("unexpected end of input");
        }
        switch (text_[pos_]) {
            case '{':
                return object(out, depth);
            case '[':
                return array(out, depth);
            case '"': {
                std::string s;
                if (!string(s)) {
                    return false;
                }
                out.value = std::move(s);
                return true;
            }
            case 't':
                out.value = true;
                return literal("true");
            case 'f':
                out.value = false;
                return literal("false");
            case 'n':
                out.value = nullptr;
                return literal("null");
            default:
                return number(out);
        }
    }

    bool object(JsonValue& out, int depth) {
        ++pos_;
        JsonObject obj;
        skip_space();
        if (pos_ < text_.size() && text_[pos_] == '}') {
            ++pos_;
            out.value = std::move(obj);
            return true;
        }
        while (true) {
            skip_space();
            std::string key;
            if (pos_ >= text_.size() || text_[pos_] != '"') {
                return fail("expected a string key");
            }
            if (!string(key)) {
                return false;
            }
            skip_space();
            if (pos_ >= text_.size() || text_[pos_] != ':') {
                return fail("expected ':'");
            }
            ++pos_;
            skip_space();
            JsonValue v;
            if (!value(v, depth + 1)) {
                return false;
            }
            obj.push_back(JsonMember{std::move(key), std::move(v)});
            skip_space();
            if (pos_ < text_.size() && text_[pos_] == ',') {
                ++pos_;
                continue;
            }
            if (pos_ < text_.size() && text_[pos_] == '}') {
                ++pos_;
                out.value = std::move(obj);
                return true;
            }
            return fail("expected ',' or '}'");
        }
    }

    bool array(JsonValue& out, int depth) {
        ++pos_;
        JsonArray arr;
        skip_space();
        if (pos_ < text_.size() && text_[pos_] == ']') {
            ++pos_;
            out.value = std::move(arr);
            return true;
        }
        while (true) {
            skip_space();
            JsonValue v;
            if (!value(v, depth + 1)) {
                return false;
            }
            arr.push_back(std::move(v));
            skip_space();
            if (pos_ < text_.size() && text_[pos_] == ',') {
                ++pos_;
                continue;
            }
            if (pos_ < text_.size() && text_[pos_] == ']') {
                ++pos_;
                out.value = std::move(arr);
                return true;
            }
            return fail("expected ',' or ']'");
        }
    }

    bool hex4(std::uint32_t& cp) {
        if (pos_ + 4 > text_.size()) {
            return fail("short \\u escape");
        }
        cp = 0;
        for (int i = 0; i < 4; ++i) {
            const char c = text_[pos_++];
            cp <<= 4;
            if (c >= '0' && c <= '9') {
                cp |= static_cast<std::uint32_t>(c - '0');
            } else if (c >= 'a' && c <= 'f') {
                cp |= static_cast<std::uint32_t>(c - 'a' + 10);
            } else if (c >= 'A' && c <= 'F') {
                cp |= static_cast<std::uint32_t>(c - 'A' + 10);
            } else {
                return fail("bad hex digit in \\u escape");
            }
        }
        return true;
    }

    static void append_utf8(std::string& s, std::uint32_t cp) {
        if (cp < 0x800) {
            s += static_cast<char>(0xC0 | (cp >> 6));
        } else if (cp < 0x10000) {
            s += static_cast<char>(0xE0 | (cp >> 12));
            s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        } else {
            s += static_cast<char>(0xF0 | (cp >> 18));
            s += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
            s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        }
        s += static_cast<char>(0x80 | (cp & 0x3F));
    }

    bool string(std::string& out) {
        ++pos_;
        while (pos_ < text_.size()) {
            const char c = text_[pos_++];
            if (c == '"') {
                return true;
            }
            if (static_cast<unsigned char>(c) < 0x20) {
                return fail("control character in string");
            }
            if (c != '\\') {
                out += c;
                continue;
            }
            if (pos_ >= text_.size()) {
                break;
            }
            const char e = text_[pos_++];
            switch (e) {
                case '"':
                case '\\':
                case '/':
                    out += e;
                    break;
                case 'b':
                    out += '\b';
                    break;
                case 'f':
                    out += '\f';
                    break;
                case 'n':
                    out += '\n';
                    break;
                case 'r':
                    out += '\r';
                    break;
                case 't':
                    out += '\t';
                    break;
                case 'u': {
                    std::uint32_t cp = 0;
                    if (!hex4(cp)) {
                        return false;
                    }
                    if (cp <= 0xFF) {
                        out += static_cast<char>(cp);  // one byte: see append_json_string
                    } else if (cp >= 0xD800 && cp <= 0xDBFF) {
                        std::uint32_t low = 0;
                        if (text_.substr(pos_, 2) != "\\u") {
                            return fail("unpaired surrogate");
                        }
                        pos_ += 2;
                        if (!hex4(low) || low < 0xDC00 || low > 0xDFFF) {
                            return fail("unpaired surrogate");
                        }
                        append_utf8(out, 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00));
                    } else {
                        append_utf8(out, cp);
                    }
                    break;
                }
                default:
                    return fail("unknown escape in string");
            }
        }
        return fail("unterminated string");
    }

    bool number(JsonValue& out) {
        const std::size_t start = pos_;
        if (pos_ < text_.size() && text_[pos_] == '-') {
            ++pos_;
        }
        const std::size_t digits = pos_;
        while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') {
            ++pos_;
        }
        if (pos_ == digits) {
            return fail("expected a value");
        }
        if (pos_ < text_.size() && text_[pos_] == '.') {
            ++pos_;
            const std::size_t frac = pos_;
            while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') {
                ++pos_;
            }
            if (pos_ == frac) {
                return fail("digits expected after '.'");
            }
        }
        if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
            ++pos_;
            if (pos_ < text_.size() && (text_[pos_] == '+' || text_[pos_] == '-')) {
                ++pos_;
            }
            const std::size_t exp = pos_;
            while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') {
                ++pos_;
            }
            if (pos_ == exp) {
                return fail("digits expected in exponent");
            }
        }
        out.value = JsonNumber{std::string(text_.substr(start, pos_ - start))};
        return true;
    }

    std::string_view text_;
    std::size_t pos_ = 0;
    std::string error_;
};

}  // namespace

const std::string* JsonValue::as_string() const {
    return std::get_if<std::string>(&value);
}
const JsonNumber* JsonValue::as_number() const {
    return std::get_if<JsonNumber>(&value);
}
const JsonArray* JsonValue::as_array() const {
    return std::get_if<JsonArray>(&value);
}
const JsonObject* JsonValue::as_object() const {
    return std::get_if<JsonObject>(&value);
}

bool JsonNumber::is_integer() const {
    return text.find_first_of(".eE") == std::string::npos;
}

const JsonValue* JsonValue::member(std::string_view key) const {
    const auto* obj = as_object();
    if (obj == nullptr) {
        return nullptr;
    }
    for (const auto& [k, v] : *obj) {
        if (k == key) {
            return &v;
        }
    }
    return nullptr;
}

JsonParseResult parse_json(std::string_view text) {
    return Reader(text).run();
}

void append_json_string(std::string& out, std::string_view text) {
    out += '"';
    for (const char c : text) {
        const auto b = static_cast<unsigned char>(c);
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (b < 0x20 || b >= 0x7F) {
            char esc[8];
            std::snprintf(esc, sizeof esc, "\\u%04x", b);
            out += esc;
        } else {
            out += c;
        }
    }
    out += '"';
}

}  // namespace airseg::mavdump
