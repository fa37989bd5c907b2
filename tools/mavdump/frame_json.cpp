#include "tools/mavdump/frame_json.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <span>
#include <system_error>
#include <utility>

#include <nlohmann/json.hpp>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/field_value.hpp"
#include "services/autopilot/mavlink/message_table.hpp"

namespace airseg::mavdump {
namespace {

using mavlink::FieldInfo;
using mavlink::FieldType;
using mavlink::FieldValue;

void append_hex(std::string& out, std::span<const std::uint8_t> bytes) {
    static constexpr char kDigits[] = "0123456789abcdef";
    for (std::uint8_t b : bytes) {
        out += kDigits[b >> 4];
        out += kDigits[b & 0xF];
    }
}

void append_json_string(std::string& out, std::string_view text) {
    out += '"';
    for (const char c : text) {
        const auto b = static_cast<unsigned char>(c);
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (b < 0x20 || b >= 0x7F) {
            // A char[] field holds bytes, not text: byte 0xNN becomes \u00NN (field_bytes reads it back).
            static constexpr char kDigits[] = "0123456789abcdef";
            out += "\\u00";
            out += kDigits[b >> 4];
            out += kDigits[b & 0xF];
        } else {
            out += c;
        }
    }
    out += '"';
}

template <class T>
void append_number(std::string& out, T value) {
    std::array<char, 40> buf{};
    const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), value);
    out.append(buf.data(), res.ptr);
}

void append_element(std::string& out, const FieldInfo& field, std::span<const std::uint8_t> payload,
                    std::size_t i) {
    const FieldValue v = mavlink::read_element(field, payload, i);
    if (const auto* s = std::get_if<std::int64_t>(&v)) {
        append_number(out, *s);
    } else if (const auto* u = std::get_if<std::uint64_t>(&v)) {
        append_number(out, *u);
    } else {
        const double d = std::get<double>(v);
        if (std::isnan(d)) {
            out += "\"nan\"";
        } else if (std::isinf(d)) {
            out += d > 0 ? "\"inf\"" : "\"-inf\"";
        } else if (field.type == FieldType::Float) {
            append_number(out, static_cast<float>(d));  // shortest text that reads back as the same float
        } else {
            append_number(out, d);
        }
    }
}

void append_field(std::string& out, const FieldInfo& field, std::span<const std::uint8_t> payload) {
    if (field.type == FieldType::Char && field.array_length > 0) {
        const auto* begin = reinterpret_cast<const char*>(payload.data() + field.offset);
        std::string_view text(begin, field.array_length);
        text = text.substr(0, text.find('\0'));
        append_json_string(out, text);
    } else if (field.array_length > 0) {
        out += '[';
        for (std::size_t i = 0; i < field.array_length; ++i) {
            if (i > 0) {
                out += ',';
            }
            append_element(out, field, payload, i);
        }
        out += ']';
    } else {
        append_element(out, field, payload, 0);
    }
}

// ---- encoding ----

using Json = nlohmann::json;

// Enough for any frame document (three levels) and for keys a reader ignores; bounds the parser's work and
// memory on a hostile line.
constexpr int kMaxJsonNesting = 32;

struct NestingTooDeep {};

// The text of a parse error without its "[json.exception...] parse error at line 1, column N: " prefix and
// without the token it quotes ("; last read: '...'"), which can be long and hold raw input bytes; the caller
// names the byte instead.
std::string parse_error_text(const Json::parse_error& e) {
    std::string text = e.what();
    if (const auto colon = text.find(": "); colon != std::string::npos) {
        text.erase(0, colon + 2);
    }
    static constexpr std::string_view kLastRead = "; last read: '";
    if (const auto from = text.find(kLastRead); from != std::string::npos) {
        const auto expected = text.rfind("'; expected ");
        text.erase(from, expected != std::string::npos && expected >= from + kLastRead.size()
                             ? expected + 1 - from
                             : std::string::npos);
    }
    return text;
}

std::optional<Json> parse_line(std::string_view line, std::string& error) {
    const Json::parser_callback_t refuse_deep_nesting = [](int depth, Json::parse_event_t event, Json&) {
        if ((event == Json::parse_event_t::object_start || event == Json::parse_event_t::array_start) &&
            depth >= kMaxJsonNesting) {
            throw NestingTooDeep{};
        }
        return true;
    };
    try {
        return Json::parse(line, refuse_deep_nesting);
    } catch (const Json::parse_error& e) {
        // e.byte counts from 1 and points at the last byte read.
        error = parse_error_text(e) + " at byte " + std::to_string(e.byte > 0 ? e.byte - 1 : 0);
    } catch (const Json::out_of_range&) {
        error = "number out of range";
    } catch (const NestingTooDeep&) {
        error = "nested deeper than " + std::to_string(kMaxJsonNesting) + " levels";
    }
    return std::nullopt;
}

const Json* member(const Json& object, const char* key) {
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
}

// Integers of any field width convert exactly: nlohmann::json keeps them as int64_t or uint64_t.
template <class T>
std::optional<T> integer_of(const Json* v) {
    if (v != nullptr && v->is_number_unsigned()) {
        const auto u = v->get<std::uint64_t>();
        if (std::in_range<T>(u)) {
            return static_cast<T>(u);
        }
    } else if (v != nullptr && v->is_number_integer()) {
        const auto i = v->get<std::int64_t>();
        if (std::in_range<T>(i)) {
            return static_cast<T>(i);
        }
    }
    return std::nullopt;
}

// JSON text is Unicode; a char[] field holds bytes. Code points up to U+00FF (what append_json_string writes
// for bytes 0x80-0xFF) become one byte each; higher code points keep their UTF-8 bytes.
std::string field_bytes(const std::string& utf8) {
    std::string out;
    for (std::size_t i = 0; i < utf8.size(); ++i) {
        const auto lead = static_cast<unsigned char>(utf8[i]);
        if ((lead == 0xC2 || lead == 0xC3) && i + 1 < utf8.size()) {
            const auto next = static_cast<unsigned char>(utf8[++i]);
            out += static_cast<char>(((lead & 0x03) << 6) | (next & 0x3F));
        } else {
            out += utf8[i];
        }
    }
    return out;
}

std::optional<FieldValue> element_value(const Json& v, const FieldInfo& field, std::string& error) {
    const bool is_float = field.type == FieldType::Float || field.type == FieldType::Double;
    if (v.is_string() && is_float) {
        const auto& s = v.get_ref<const std::string&>();
        if (s == "nan") {
            return std::numeric_limits<double>::quiet_NaN();
        }
        if (s == "inf") {
            return std::numeric_limits<double>::infinity();
        }
        if (s == "-inf") {
            return -std::numeric_limits<double>::infinity();
        }
    }
    if (v.is_number_unsigned()) {
        return FieldValue{v.get<std::uint64_t>()};
    }
    if (v.is_number_integer()) {
        return FieldValue{v.get<std::int64_t>()};
    }
    if (!v.is_number_float()) {
        error = is_float ? "expects a number or \"nan\", \"inf\", \"-inf\"" : "expects an integer";
        return std::nullopt;
    }
    const double d = v.get<double>();
    if (is_float) {
        return FieldValue{d};
    }
    // Integers beyond 64 bits reach here as doubles.
    constexpr double kTwoTo63 = 9223372036854775808.0;
    if (std::trunc(d) == d && (d <= -kTwoTo63 || d >= 2 * kTwoTo63)) {
        error = "integer out of range";
    } else {
        error = "expects an integer, got " + v.dump();
    }
    return std::nullopt;
}

bool store_element(const Json& v, const FieldInfo& field, std::span<std::uint8_t> payload, std::size_t index,
                   std::string& error) {
    const auto value = element_value(v, field, error);
    if (!value) {
        return false;
    }
    switch (mavlink::write_element(field, payload, index, *value)) {
        case mavlink::WriteResult::Ok:
            return true;
        case mavlink::WriteResult::OutOfRange:
            error = std::string("value out of range for ") + std::string(mavlink::type_name(field.type));
            return false;
        case mavlink::WriteResult::WrongKind:
            error = "expects an integer";
            return false;
    }
    return false;
}

bool store_field(const Json& v, const FieldInfo& field, std::span<std::uint8_t> payload, std::string& error) {
    if (field.type == FieldType::Char && field.array_length > 0) {
        if (!v.is_string()) {
            error = "expects a string";
            return false;
        }
        const std::string bytes = field_bytes(v.get_ref<const std::string&>());
        if (bytes.size() > field.array_length) {
            error = "string longer than " + std::to_string(field.array_length) + " bytes";
            return false;
        }
        std::copy(bytes.begin(), bytes.end(), payload.begin() + field.offset);
        return true;
    }
    if (field.array_length > 0) {
        if (!v.is_array()) {
            error = "expects an array";
            return false;
        }
        if (v.size() > field.array_length) {
            error = "array longer than " + std::to_string(field.array_length) + " elements";
            return false;
        }
        for (std::size_t i = 0; i < v.size(); ++i) {
            if (!store_element(v[i], field, payload, i, error)) {
                error = "element " + std::to_string(i) + ": " + error;
                return false;
            }
        }
        return true;
    }
    return store_element(v, field, payload, 0, error);
}

std::optional<std::vector<std::uint8_t>> hex_bytes(const std::string& hex) {
    if (hex.size() % 2 != 0 || hex.size() > 2 * mavlink::kMaxPayload) {
        return std::nullopt;
    }
    std::vector<std::uint8_t> out;
    for (std::size_t i = 0; i < hex.size(); i += 2) {
        std::uint8_t b = 0;
        const auto res = std::from_chars(hex.data() + i, hex.data() + i + 2, b, 16);
        if (res.ec != std::errc{} || res.ptr != hex.data() + i + 2) {
            return std::nullopt;
        }
        out.push_back(b);
    }
    return out;
}

}  // namespace

std::string frame_to_json(const mavlink::Frame& frame, std::optional<std::uint64_t> timestamp_us) {
    const mavlink::MessageInfo* info =
        frame.checksum_verified ? mavlink::find_dialect_message(frame.msgid) : nullptr;
    std::string out;
    out.reserve(256);
    out += '{';
    if (timestamp_us) {
        out += "\"timestamp_us\":";
        append_number(out, *timestamp_us);
        out += ',';
    }
    out += "\"name\":\"";
    if (info != nullptr) {
        out += info->name;
    } else {
        out += "UNKNOWN_";
        append_number(out, frame.msgid);
    }
    out += "\",\"msgid\":";
    append_number(out, frame.msgid);
    out += ",\"sysid\":";
    append_number(out, frame.sysid);
    out += ",\"compid\":";
    append_number(out, frame.compid);
    out += ",\"seq\":";
    append_number(out, frame.seq);
    out += ",\"v\":";
    out += frame.version == mavlink::Version::V1 ? '1' : '2';
    if (frame.is_signed) {
        out += ",\"signed\":true";
    }
    if (info == nullptr) {
        out += ",\"payload\":\"";
        append_hex(out, frame.payload_view());
        out += "\"}";
        return out;
    }
    out += ",\"fields\":{";
    bool first = true;
    for (std::uint8_t index : info->declaration_order) {
        const FieldInfo& field = info->fields[index];
        if (!first) {
            out += ',';
        }
        first = false;
        out += '"';
        out += field.name;
        out += "\":";
        append_field(out, field, frame.payload_view());
    }
    out += "}}";
    return out;
}

std::string message_to_json(const mavlink::MessageInfo& message) {
    std::string out = "{\"name\":\"";
    out += message.name;
    out += "\",\"msgid\":";
    append_number(out, message.id);
    out += ",\"crc_extra\":";
    append_number(out, message.crc_extra);
    out += ",\"min_length\":";
    append_number(out, message.base_length);
    out += ",\"length\":";
    append_number(out, message.length);
    out += message.typed ? ",\"typed\":true" : ",\"typed\":false";
    out += ",\"fields\":[";
    bool first = true;
    for (std::uint8_t index : message.declaration_order) {
        const FieldInfo& field = message.fields[index];
        out += first ? "{\"name\":\"" : ",{\"name\":\"";
        first = false;
        out += field.name;
        out += "\",\"type\":\"";
        out += mavlink::type_name(field.type);
        out += '"';
        if (field.array_length > 0) {
            out += ",\"length\":";
            append_number(out, field.array_length);
        }
        if (field.extension) {
            out += ",\"extension\":true";
        }
        out += '}';
    }
    out += "]}";
    return out;
}

JsonFrameEncoder::Result JsonFrameEncoder::encode_line(std::string_view line) {
    Result r;
    std::string json_error;
    const std::optional<Json> parsed = parse_line(line, json_error);
    if (!parsed) {
        r.error = "invalid JSON: " + json_error;
        return r;
    }
    const Json& doc = *parsed;
    if (!doc.is_object()) {
        r.error = "expected a JSON object";
        return r;
    }
    const Json* name = member(doc, "name");
    const Json* msgid_value = member(doc, "msgid");
    const mavlink::MessageInfo* info = nullptr;
    std::uint32_t msgid = 0;
    if (name != nullptr) {
        if (!name->is_string()) {
            r.error = "\"name\" must be a string";
            return r;
        }
        const auto& name_text = name->get_ref<const std::string&>();
        info = mavlink::find_dialect_message(name_text);
        if (info == nullptr && msgid_value == nullptr) {
            r.error = "unknown message name \"" + name_text + "\" (give \"msgid\" to send it raw)";
            return r;
        }
    }
    if (msgid_value != nullptr) {
        const auto id = integer_of<std::uint32_t>(msgid_value);
        if (!id || *id > 0xFFFFFF) {
            r.error = "\"msgid\" must be an integer from 0 to 16777215";
            return r;
        }
        if (info != nullptr && info->id != *id) {
            r.error = "\"name\" " + std::string(info->name) + " has msgid " + std::to_string(info->id) +
                      ", not " + std::to_string(*id);
            return r;
        }
        msgid = *id;
        if (info == nullptr) {
            info = mavlink::find_dialect_message(msgid);
        }
    } else if (info != nullptr) {
        msgid = info->id;
    } else {
        r.error = "a frame needs \"name\" or \"msgid\"";
        return r;
    }

    mavlink::FrameHeader header;
    header.msgid = msgid;
    const Json* version_value = member(doc, "v");
    const auto version = version_value ? integer_of<int>(version_value) : std::optional<int>(2);
    if (!version || (*version != 1 && *version != 2)) {
        r.error = "\"v\" must be 1 or 2";
        return r;
    }
    header.version = *version == 1 ? mavlink::Version::V1 : mavlink::Version::V2;
    for (auto [key, target, fallback] : {std::tuple{"sysid", &header.sysid, std::uint8_t{255}},
                                         std::tuple{"compid", &header.compid, std::uint8_t{190}}}) {
        const Json* v = member(doc, key);
        const auto value = v ? integer_of<std::uint8_t>(v) : std::optional<std::uint8_t>(fallback);
        if (!value) {
            r.error = std::string("\"") + key + "\" must be an integer from 0 to 255";
            return r;
        }
        *target = *value;
    }
    std::uint8_t& next = next_seq_[{header.sysid, header.compid}];
    if (const Json* v = member(doc, "seq")) {
        const auto seq = integer_of<std::uint8_t>(v);
        if (!seq) {
            r.error = "\"seq\" must be an integer from 0 to 255";
            return r;
        }
        next = *seq;
    }
    header.seq = next++;

    std::array<std::uint8_t, mavlink::kMaxFrameLength> out{};
    std::size_t size = 0;
    if (info == nullptr) {
        const Json* payload = member(doc, "payload");
        const auto crc_extra = integer_of<std::uint8_t>(member(doc, "crc_extra"));
        if (payload == nullptr || !payload->is_string() || !crc_extra) {
            r.error = "message id " + std::to_string(msgid) +
                      " is not known: give its raw \"payload\" (hex) and its \"crc_extra\"";
            return r;
        }
        const auto bytes = hex_bytes(payload->get_ref<const std::string&>());
        if (!bytes) {
            r.error = "\"payload\" must be an even number of hex digits, at most 255 bytes";
            return r;
        }
        size = mavlink::encode_frame(header, *crc_extra, *bytes, out);
    } else {
        std::array<std::uint8_t, mavlink::kMaxPayload> payload{};
        if (info->id == mavlink::Heartbeat::kId) {
            // Like every MAVLink encoder, fill in the protocol version a sender does not choose.
            mavlink::write_element(*info->find_field("mavlink_version"), payload, 0,
                                   std::uint64_t{mavlink::kMavlinkDialectVersion});
        }
        if (const Json* fields = member(doc, "fields")) {
            if (!fields->is_object()) {
                r.error = "\"fields\" must be an object";
                return r;
            }
            for (const auto& [key, value] : fields->items()) {
                const FieldInfo* field = info->find_field(key);
                if (field == nullptr) {
                    r.error = std::string(info->name) + " has no field \"" + key + "\"";
                    return r;
                }
                std::string error;
                if (!store_field(value, *field, payload, error)) {
                    r.error = std::string(info->name) + "." + key + ": " + error;
                    return r;
                }
            }
        }
        size = mavlink::encode_message(header, *info, std::span(payload).first(info->length), out);
    }
    if (size == 0) {
        r.error =
            "message id " + std::to_string(msgid) + " cannot be sent as MAVLink 1 (ids above 255 need v2)";
        return r;
    }
    r.frame.assign(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(size));
    return r;
}

}  // namespace airseg::mavdump
