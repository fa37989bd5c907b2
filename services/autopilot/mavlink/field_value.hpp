#pragma once
// Reading and writing one element of a field in a payload through its FieldInfo, for code that handles
// messages generically (airseg-mavdump). Typed code uses the structs of messages.hpp instead.
#include <cstddef>
#include <cstdint>
#include <span>
#include <variant>

#include "services/autopilot/mavlink/field.hpp"

namespace airseg::mavlink {

/// A field element widened without loss: signed integers as int64, unsigned (and char) as uint64,
/// float and double as double.
using FieldValue = std::variant<std::int64_t, std::uint64_t, double>;

/// Element `index` of `field` in a full-length payload (payload.size() >= field.offset + field.size()).
FieldValue read_element(const FieldInfo& field, std::span<const std::uint8_t> payload, std::size_t index);

enum class WriteResult : std::uint8_t { Ok, OutOfRange, WrongKind };

/// Stores `value` as element `index` of `field`. Integers must fit the field's type (OutOfRange otherwise);
/// a float/double value for an integer field is WrongKind; an integer for a float field converts.
WriteResult write_element(const FieldInfo& field, std::span<std::uint8_t> payload, std::size_t index,
                          FieldValue value);

}  // namespace airseg::mavlink
