#pragma once
// The run-time catalogues of MAVLink messages: what a generic tool (airseg-mavdump) or the parser needs to
// know about a message id without its C++ type. Two, both built at compile time:
//  - the typed messages (all_messages, find_message): those of messages.def, from the same declarations as
//    the structs of messages.hpp; the code that acts on messages uses these;
//  - ArduPilot's whole dialect (dialect_messages, find_dialect_message): dialect.def, generated from the
//    MAVLink definition XML. The parser verifies every frame of it, so any of its frames can be checked and
//    forwarded; only those with `typed` set are decoded by the daemon. Every typed message is also a dialect
//    message with the same layout (tests/unit/mavlink/dialect_test.cpp checks it).
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
    bool typed = false;  // declared in messages.def: a struct of messages.hpp decodes it

    /// The field called `name`, or nullptr.
    const FieldInfo* find_field(std::string_view field_name) const;
};

/// Every known message, ordered by id.
std::span<const MessageInfo> all_messages();
/// The message with this id, or nullptr when the id is not in messages.def.
const MessageInfo* find_message(std::uint32_t id);
/// The message with this name ("HEARTBEAT"), or nullptr.
const MessageInfo* find_message(std::string_view name);

/// Every message of ArduPilot's dialect, ordered by id.
std::span<const MessageInfo> dialect_messages();
/// The dialect message with this id, or nullptr: the parser verifies a frame only when this finds its id.
const MessageInfo* find_dialect_message(std::uint32_t id);
/// The dialect message with this name, or nullptr.
const MessageInfo* find_dialect_message(std::string_view name);

}  // namespace airseg::mavlink
