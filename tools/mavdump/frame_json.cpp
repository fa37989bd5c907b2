#include "tools/mavdump/frame_json.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <span>
#include <system_error>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/field_value.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "tools/mavdump/json.hpp"

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

template <class T>
std::optional<T> integer_of(const JsonValue* v) {
    if (v == nullptr) {
        return std::nullopt;
    }
    const JsonNumber* n = v->as_number();
    if (n == nullptr || !n->is_integer()) {
        return std::nullopt;
    }
    T out{};
    const auto res = std::from_chars(n->text.data(), n->text.data() + n->text.size(), out);
    if (res.ec != std::errc{} || res.ptr != n->text.data() + n->text.size()) {
        return std::nullopt;
    }
    return out;
}

std::optional<FieldValue> element_value(const JsonValue& v, const FieldInfo& field, std::string& error) {
    const bool is_float = field.type == FieldType::Float || field.type == FieldType::Double;
    if (const std::string* s = v.as_string(); s != nullptr && is_float) {
        if (*s == "nan") {
            return std::numeric_limits<double>::quiet_NaN();
        }
        if (*s == "inf") {
            return std::numeric_limits<double>::infinity();
        }
        if (*s == "-inf") {
            return -std::numeric_limits<double>::infinity();
        }
    }
    const JsonNumber* n = v.as_number();
    if (n == nullptr) {
        error = is_float ? "expects a number or \"nan\", \"inf\", \"-inf\"" : "expects an integer";
        return std::nullopt;
    }
    if (n->is_integer()) {
        if (n->text.front() == '-') {
            if (auto i = integer_of<std::int64_t>(&v)) {
                return FieldValue{*i};
            }
        } else if (auto u = integer_of<std::uint64_t>(&v)) {
            return FieldValue{*u};
        }
        if (!is_float) {
            error = "integer out of range";
            return std::nullopt;
        }
    }
    if (!is_float) {
        error = "expects an integer, got " + n->text;
        return std::nullopt;
    }
    double d = 0;
    const auto res = std::from_chars(n->text.data(), n->text.data() + n->text.size(), d);
    if (res.ec != std::errc{}) {
        error = "number out of range: " + n->text;
        return std::nullopt;
    }
    return FieldValue{d};
}

bool store_element(const JsonValue& v, const FieldInfo& field, std::span<std::uint8_t> payload,
                   std::size_t index, std::string& error) {
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

bool store_field(const JsonValue& v, const FieldInfo& field, std::span<std::uint8_t> payload,
                 std::string& error) {
    if (field.type == FieldType::Char && field.array_length > 0) {
        const std::string* s = v.as_string();
        if (s == nullptr) {
            error = "expects a string";
            return false;
        }
        if (s->size() > field.array_length) {
            error = "string longer than " + std::to_string(field.array_length) + " bytes";
            return false;
        }
        std::copy(s->begin(), s->end(), payload.begin() + field.offset);
        return true;
    }
    if (field.array_length > 0) {
        const JsonArray* a = v.as_array();
        if (a == nullptr) {
            error = "expects an array";
            return false;
        }
        if (a->size() > field.array_length) {
            error = "array longer than " + std::to_string(field.array_length) + " elements";
            return false;
        }
        for (std::size_t i = 0; i < a->size(); ++i) {
            if (!store_element((*a)[i], field, payload, i, error)) {
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
    const mavlink::MessageInfo* info = frame.checksum_verified ? mavlink::find_message(frame.msgid) : nullptr;
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

JsonFrameEncoder::Result JsonFrameEncoder::encode_line(std::string_view line) {
    Result r;
    const JsonParseResult parsed = parse_json(line);
    if (!parsed.value) {
        r.error = "invalid JSON: " + parsed.error;
        return r;
    }
    const JsonValue& doc = *parsed.value;
    if (doc.as_object() == nullptr) {
        r.error = "expected a JSON object";
        return r;
    }
    const JsonValue* name = doc.member("name");
    const JsonValue* msgid_value = doc.member("msgid");
    const mavlink::MessageInfo* info = nullptr;
    std::uint32_t msgid = 0;
    if (name != nullptr) {
        if (name->as_string() == nullptr) {
            r.error = "\"name\" must be a string";
            return r;
        }
        info = mavlink::find_message(*name->as_string());
        if (info == nullptr && msgid_value == nullptr) {
            r.error = "unknown message name \"" + *name->as_string() + "\" (give \"msgid\" to send it raw)";
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
            info = mavlink::find_message(msgid);
        }
    } else if (info != nullptr) {
        msgid = info->id;
    } else {
        r.error = "a frame needs \"name\" or \"msgid\"";
        return r;
    }

    mavlink::FrameHeader header;
    header.msgid = msgid;
    const auto version = doc.member("v") ? integer_of<int>(doc.member("v")) : std::optional<int>(2);
    if (!version || (*version != 1 && *version != 2)) {
        r.error = "\"v\" must be 1 or 2";
        return r;
    }
    header.version = *version == 1 ? mavlink::Version::V1 : mavlink::Version::V2;
    for (auto [key, target, fallback] : {std::tuple{"sysid", &header.sysid, std::uint8_t{255}},
                                         std::tuple{"compid", &header.compid, std::uint8_t{190}}}) {
        const JsonValue* v = doc.member(key);
        const auto value = v ? integer_of<std::uint8_t>(v) : std::optional<std::uint8_t>(fallback);
        if (!value) {
            r.error = std::string("\"") + key + "\" must be an integer from 0 to 255";
            return r;
        }
        *target = *value;
    }
    std::uint8_t& next = next_seq_[{header.sysid, header.compid}];
    if (const JsonValue* v = doc.member("seq")) {
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
        const JsonValue* payload = doc.member("payload");
        const auto crc_extra = integer_of<std::uint8_t>(doc.member("crc_extra"));
        if (payload == nullptr || payload->as_string() == nullptr || !crc_extra) {
            r.error = "message id " + std::to_string(msgid) +
                      " is not known: give its raw \"payload\" (hex) and its \"crc_extra\"";
            return r;
        }
        const auto bytes = hex_bytes(*payload->as_string());
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
        if (const JsonValue* fields = doc.member("fields")) {
            if (fields->as_object() == nullptr) {
                r.error = "\"fields\" must be an object";
                return r;
            }
            for (const auto& [key, value] : *fields->as_object()) {
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
