#pragma once
// The vocabulary of MAVLink message fields: wire types, the declaration of one field as written in the
// message definition XML, and the derived wire layout of one field.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <type_traits>

namespace airseg::mavlink {

enum class FieldType : std::uint8_t {
    Char,
    Uint8,
    Int8,
    Uint16,
    Int16,
    Uint32,
    Int32,
    Uint64,
    Int64,
    Float,
    Double
};

/// Size in bytes of one element of this type on the wire.
constexpr std::size_t type_size(FieldType t) {
    switch (t) {
        case FieldType::Char:
        case FieldType::Uint8:
        case FieldType::Int8:
            return 1;
        case FieldType::Uint16:
        case FieldType::Int16:
            return 2;
        case FieldType::Uint32:
        case FieldType::Int32:
        case FieldType::Float:
            return 4;
        case FieldType::Uint64:
        case FieldType::Int64:
        case FieldType::Double:
            return 8;
    }
    return 0;
}

/// The type's name as the MAVLink XML spells it; CRC_EXTRA hashes these names.
/// (The XML's "uint8_t_mavlink_version" is hashed as "uint8_t", so it needs no type of its own.)
constexpr std::string_view type_name(FieldType t) {
    switch (t) {
        case FieldType::Char:
            return "char";
        case FieldType::Uint8:
            return "uint8_t";
        case FieldType::Int8:
            return "int8_t";
        case FieldType::Uint16:
            return "uint16_t";
        case FieldType::Int16:
            return "int16_t";
        case FieldType::Uint32:
            return "uint32_t";
        case FieldType::Int32:
            return "int32_t";
        case FieldType::Uint64:
            return "uint64_t";
        case FieldType::Int64:
            return "int64_t";
        case FieldType::Float:
            return "float";
        case FieldType::Double:
            return "double";
    }
    return "";
}

// The definition files (messages.def, dialect.def) name the field types as the XML does: uint8_t, not
// std::uint8_t.
using std::int16_t;
using std::int32_t;
using std::int64_t;
using std::int8_t;
using std::uint16_t;
using std::uint32_t;
using std::uint64_t;
using std::uint8_t;

/// FieldTypeOf<T>::value: the wire type of C++ type T (or of an array's elements).
template <class T>
struct FieldTypeOf;
// One row a wire type, so the mapping reads as the table it is.
#define AIRSEG_MAVLINK_FIELD_TYPE_OF(CppType_, FieldType_) \
    template <>                                            \
    struct FieldTypeOf<CppType_> : std::integral_constant<FieldType, FieldType::FieldType_> {};
AIRSEG_MAVLINK_FIELD_TYPE_OF(char, Char)
AIRSEG_MAVLINK_FIELD_TYPE_OF(std::uint8_t, Uint8)
AIRSEG_MAVLINK_FIELD_TYPE_OF(std::int8_t, Int8)
AIRSEG_MAVLINK_FIELD_TYPE_OF(std::uint16_t, Uint16)
AIRSEG_MAVLINK_FIELD_TYPE_OF(std::int16_t, Int16)
AIRSEG_MAVLINK_FIELD_TYPE_OF(std::uint32_t, Uint32)
AIRSEG_MAVLINK_FIELD_TYPE_OF(std::int32_t, Int32)
AIRSEG_MAVLINK_FIELD_TYPE_OF(std::uint64_t, Uint64)
AIRSEG_MAVLINK_FIELD_TYPE_OF(std::int64_t, Int64)
AIRSEG_MAVLINK_FIELD_TYPE_OF(float, Float)
AIRSEG_MAVLINK_FIELD_TYPE_OF(double, Double)
#undef AIRSEG_MAVLINK_FIELD_TYPE_OF
template <class T, std::size_t N>
struct FieldTypeOf<std::array<T, N>> : FieldTypeOf<T> {};

template <class T>
struct ArrayLengthOf {
    static constexpr std::uint8_t value = 0;
};
template <class T, std::size_t N>
struct ArrayLengthOf<std::array<T, N>> {
    static_assert(N > 0 && N < 256);
    static constexpr std::uint8_t value = static_cast<std::uint8_t>(N);
};

/// One entry of a message declaration, in XML order. The `<extensions/>` separator is an entry of its own
/// (is_extensions_marker) so a declaration reads like the XML it comes from.
struct FieldDecl {
    std::string_view name;
    FieldType type = FieldType::Uint8;
    std::uint8_t array_length = 0;  // 0: a scalar
    bool is_extensions_marker = false;
};

/// One field as it sits on the wire.
struct FieldInfo {
    std::string_view name;
    FieldType type = FieldType::Uint8;
    std::uint8_t array_length = 0;  // 0: a scalar; otherwise the element count
    std::uint8_t offset = 0;        // byte offset in the (full-length) payload
    bool extension = false;  // MAVLink 2 extension field: not in CRC_EXTRA, absent from v1-length payloads

    constexpr std::size_t element_count() const { return array_length == 0 ? 1 : array_length; }
    constexpr std::size_t size() const { return type_size(type) * element_count(); }
};

}  // namespace airseg::mavlink
