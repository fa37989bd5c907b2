#pragma once
// Typed MAVLink messages, one struct per message of messages.def, members in XML declaration order with the
// specification's names. Each struct's wire layout and CRC_EXTRA (MessageTraits<M>) are derived from the same
// declaration, and encode_payload / decode_payload convert between a struct and its little-endian payload.
//
//   mavlink::Heartbeat hb;  hb.type = 10;  hb.custom_mode = 4;
//   auto frame_bytes = encoder.encode(hb);                 // encoder.hpp
//   if (auto hb = mavlink::decode<mavlink::Heartbeat>(frame)) { ... }   // frame from parser.hpp
#include <algorithm>
#include <array>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <type_traits>

#include "services/autopilot/mavlink/field.hpp"
#include "services/autopilot/mavlink/frame.hpp"
#include "services/autopilot/mavlink/layout.hpp"
#include "services/autopilot/mavlink/wire.hpp"

namespace airseg::mavlink {

/// Value of the HEARTBEAT mavlink_version field this implementation sends (the common.xml dialect version).
inline constexpr std::uint8_t kMavlinkDialectVersion = 3;

// --- the structs -------------------------------------------------------------------------------------------
#define AIRSEG_MAVLINK_MESSAGE(id_, NAME_, Type_)         \
    struct Type_ {                                        \
        static constexpr std::uint32_t kId = id_;         \
        static constexpr std::string_view kName = #NAME_; \
        using Self = Type_;
#define AIRSEG_MAVLINK_FIELD(type_, name_) type_ name_{};
#define AIRSEG_MAVLINK_ARRAY(type_, name_, length_) std::array<type_, length_> name_{};
#define AIRSEG_MAVLINK_VERSION_FIELD(name_) std::uint8_t name_ = kMavlinkDialectVersion;
#define AIRSEG_MAVLINK_EXTENSIONS()
#define AIRSEG_MAVLINK_END()                      \
    bool operator==(const Self&) const = default; \
    }                                             \
    ;
#include "services/autopilot/mavlink/messages.def"

// --- the declarations, as data -----------------------------------------------------------------------------
namespace declarations {
#define AIRSEG_MAVLINK_MESSAGE(id_, NAME_, Type_) inline constexpr FieldDecl Type_[] = {
#define AIRSEG_MAVLINK_FIELD(type_, name_) FieldDecl{#name_, FieldTypeOf<type_>::value, 0, false},
#define AIRSEG_MAVLINK_ARRAY(type_, name_, length_) \
    FieldDecl{#name_, FieldTypeOf<type_>::value, length_, false},
#define AIRSEG_MAVLINK_VERSION_FIELD(name_) FieldDecl{#name_, FieldType::Uint8, 0, false},
#define AIRSEG_MAVLINK_EXTENSIONS() FieldDecl{"", FieldType::Uint8, 0, true},
#define AIRSEG_MAVLINK_END() \
    }                        \
    ;
#include "services/autopilot/mavlink/messages.def"
}  // namespace declarations

/// MessageTraits<M>::layout: wire order, offsets, lengths and CRC_EXTRA of message M;
/// MessageTraits<M>::visit(m, f) calls f(member) for each member of m in declaration order.
template <class M>
struct MessageTraits;

#define AIRSEG_MAVLINK_MESSAGE(id_, NAME_, Type_)                                       \
    template <>                                                                         \
    struct MessageTraits<Type_> {                                                       \
        static constexpr auto layout =                                                  \
            make_layout<field_count(declarations::Type_)>(#NAME_, declarations::Type_); \
        template <class Self, class F>                                                  \
        static constexpr void visit(Self& m, F&& f) {
#define AIRSEG_MAVLINK_FIELD(type_, name_) f(m.name_);
#define AIRSEG_MAVLINK_ARRAY(type_, name_, length_) f(m.name_);
#define AIRSEG_MAVLINK_VERSION_FIELD(name_) f(m.name_);
#define AIRSEG_MAVLINK_EXTENSIONS()
#define AIRSEG_MAVLINK_END() \
    }                        \
    }                        \
    ;
#include "services/autopilot/mavlink/messages.def"

template <class M>
concept Message = requires {
    { M::kId } -> std::convertible_to<std::uint32_t>;
    MessageTraits<M>::layout;
};

namespace detail {
template <class T>
constexpr void put_member(std::uint8_t* out, const T& value) {
    wire::put(out, value);
}
template <class T, std::size_t N>
constexpr void put_member(std::uint8_t* out, const std::array<T, N>& values) {
    for (std::size_t i = 0; i < N; ++i) {
        wire::put(out + i * sizeof(T), values[i]);
    }
}
template <class T>
constexpr void get_member(const std::uint8_t* in, T& value) {
    value = wire::get<T>(in);
}
template <class T, std::size_t N>
constexpr void get_member(const std::uint8_t* in, std::array<T, N>& values) {
    for (std::size_t i = 0; i < N; ++i) {
        values[i] = wire::get<T>(in + i * sizeof(T));
    }
}
}  // namespace detail

/// Writes the full-length payload of `m` (MessageTraits<M>::layout.length bytes, extensions included) and
/// returns that length. The encoder decides how much of it goes on the wire.
template <Message M>
constexpr std::size_t encode_payload(const M& m, std::span<std::uint8_t, kMaxPayload> out) {
    constexpr auto& layout = MessageTraits<M>::layout;
    std::size_t i = 0;
    MessageTraits<M>::visit(
        m, [&](const auto& member) { detail::put_member(out.data() + layout.offset_by_decl[i++], member); });
    return layout.length;
}

/// Reads a payload as received: shorter payloads (MAVLink 2 truncation, MAVLink 1 without extensions) read
/// as if zero-extended; bytes beyond the known length (fields added by a newer definition) are ignored.
template <Message M>
constexpr M decode_payload(std::span<const std::uint8_t> payload) {
    constexpr auto& layout = MessageTraits<M>::layout;
    // Members are read straight from the payload; only a short one (what the parser delivers never is) is
    // first copied into a zeroed buffer of the message's length, not of the largest payload.
    if (payload.size() < layout.length) {
        std::array<std::uint8_t, layout.length> full{};
        std::copy(payload.begin(), payload.end(), full.begin());
        return decode_payload<M>(full);
    }
    const std::uint8_t* in = payload.data();
    M m;
    std::size_t i = 0;
    MessageTraits<M>::visit(
        m, [&](auto& member) { detail::get_member(in + layout.offset_by_decl[i++], member); });
    return m;
}

/// The message in `frame` if it carries message M, else nothing.
template <Message M>
std::optional<M> decode(const Frame& frame) {
    if (frame.msgid != M::kId) {
        return std::nullopt;
    }
    return decode_payload<M>(frame.payload_view());
}

/// Text of a char[] field: up to the first NUL, or the whole array when it is full (MAVLink strings are not
/// NUL-terminated when they fill their field).
template <std::size_t N>
constexpr std::string_view text_of(const std::array<char, N>& field) {
    const auto end = std::find(field.begin(), field.end(), '\0');
    return std::string_view(field.data(), static_cast<std::size_t>(end - field.begin()));
}

/// Stores `text` in a char[] field, cut to the field's length, the rest NUL.
template <std::size_t N>
constexpr void set_text(std::array<char, N>& field, std::string_view text) {
    field.fill('\0');
    std::copy_n(text.begin(), std::min(N, text.size()), field.begin());
}

}  // namespace airseg::mavlink
