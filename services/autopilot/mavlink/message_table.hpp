#pragma once
// The run-time catalogue of the messages in messages.def: what a generic tool (airseg-mavdump) or the parser
// needs to know about a message id without its C++ type. Built at compile time from the same declarations as
// the typed structs of messages.hpp.
#include <cstdint>
#include <span>
#include <string_view>

#include "services/autopilot/mavlink/field.hpp"

namespace airseg::mavlink {

struct MessageInfo {
    std::uint32_t id = 0;
    std::string_view name;
    std::uint8_t crc_extra = 0;
    std::uint8_t base_length = 0;       // bytes of the non-extension fields (the MAVLink 1 payload)
    std::uint8_t length = 0;            // bytes of all fields
    std::span<const FieldInfo> fields;  // wire order
    std::span<const std::uint8_t> declaration_order;  // indices into `fields`, in XML declaration order

    /// The field called `name`, or nullptr.
    const FieldInfo* find_field(std::string_view field_name) const;
};

/// Every known message, ordered by id.
std::span<const MessageInfo> all_messages();
/// The message with this id, or nullptr when the id is not in messages.def.
const MessageInfo* find_message(std::uint32_t id);
/// The message with this name ("HEARTBEAT"), or nullptr.
const MessageInfo* find_message(std::string_view name);

}  // namespace airseg::mavlink
