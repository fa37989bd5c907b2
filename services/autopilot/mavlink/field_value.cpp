#include "services/autopilot/mavlink/field_value.hpp"

#include <limits>
#include <type_traits>
#include <utility>

#include "services/autopilot/mavlink/wire.hpp"

namespace airseg::mavlink {
namespace {

template <class T>
FieldValue widen(const std::uint8_t* p) {
    const T v = wire::get<T>(p);
    if constexpr (std::is_floating_point_v<T>) {
        return static_cast<double>(v);
    } else if constexpr (std::is_signed_v<T> && !std::is_same_v<T, char>) {
        return static_cast<std::int64_t>(v);
    } else {
        return static_cast<std::uint64_t>(static_cast<std::make_unsigned_t<T>>(v));
    }
}

template <class T>
WriteResult narrow(std::uint8_t* p, const FieldValue& value) {
    if constexpr (std::is_floating_point_v<T>) {
        std::visit([&](auto v) { wire::put(p, static_cast<T>(v)); }, value);
        return WriteResult::Ok;
    } else {
        using Stored = std::conditional_t<std::is_same_v<T, char>, std::uint8_t, T>;
        if (std::holds_alternative<double>(value)) {
            return WriteResult::WrongKind;
        }
        bool fits = false;
        if (const auto* s = std::get_if<std::int64_t>(&value)) {
            fits = std::in_range<Stored>(*s);
        } else {
            fits = std::in_range<Stored>(std::get<std::uint64_t>(value));
        }
        if (!fits) {
            return WriteResult::OutOfRange;
        }
        std::visit(
            [&](auto v) {
                if constexpr (!std::is_floating_point_v<decltype(v)>) {
                    wire::put(p, static_cast<Stored>(v));
                }
            },
            value);
        return WriteResult::Ok;
    }
}

template <class F>
decltype(auto) dispatch(FieldType type, F&& f) {
    switch (type) {
        case FieldType::Char:
            return f(char{});
        case FieldType::Uint8:
            return f(std::uint8_t{});
        case FieldType::Int8:
            return f(std::int8_t{});
        case FieldType::Uint16:
            return f(std::uint16_t{});
        case FieldType::Int16:
            return f(std::int16_t{});
        case FieldType::Uint32:
            return f(std::uint32_t{});
        case FieldType::Int32:
            return f(std::int32_t{});
        case FieldType::Uint64:
            return f(std::uint64_t{});
        case FieldType::Int64:
            return f(std::int64_t{});
        case FieldType::Float:
            return f(float{});
        case FieldType::Double:
            break;
    }
    return f(double{});
}

}  // namespace

FieldValue read_element(const FieldInfo& field, std::span<const std::uint8_t> payload, std::size_t index) {
    const std::uint8_t* p = payload.data() + field.offset + index * type_size(field.type);
    return dispatch(field.type, [&](auto tag) { return widen<decltype(tag)>(p); });
}

WriteResult write_element(const FieldInfo& field, std::span<std::uint8_t> payload, std::size_t index,
                          FieldValue value) {
    std::uint8_t* p = payload.data() + field.offset + index * type_size(field.type);
    return dispatch(field.type, [&](auto tag) { return narrow<decltype(tag)>(p, value); });
}

}  // namespace airseg::mavlink
