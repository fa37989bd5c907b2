#pragma once
// A small JSON reader for airseg-mavdump --encode: one document per input line, bounded nesting depth,
// errors that name the byte offset. Numbers keep their text so integers of any width convert exactly.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace airseg::mavdump {

struct JsonValue;
struct JsonMember;
using JsonArray = std::vector<JsonValue>;
using JsonObject = std::vector<JsonMember>;  // in document order

struct JsonNumber {
    std::string text;
    bool is_integer() const;  // no fraction, no exponent
};

struct JsonValue {
    std::variant<std::nullptr_t, bool, JsonNumber, std::string, JsonArray, JsonObject> value;

    const JsonValue* member(std::string_view key) const;  // nullptr when absent or not an object
    const std::string* as_string() const;
    const JsonNumber* as_number() const;
    const JsonArray* as_array() const;
    const JsonObject* as_object() const;
};

struct JsonMember {
    std::string key;
    JsonValue value;
};

struct JsonParseResult {
    std::optional<JsonValue> value;
    std::string error;  // set when value is empty: what was wrong and at which byte
};

JsonParseResult parse_json(std::string_view text);

/// Appends `text` as a JSON string literal; bytes 0x80-0xFF are written as \u0080-\u00FF so that any byte
/// string survives the round trip through parse_json (which maps \u0000-\u00FF back to single bytes).
void append_json_string(std::string& out, std::string_view text);

}  // namespace airseg::mavdump
