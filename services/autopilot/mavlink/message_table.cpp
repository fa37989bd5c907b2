#include "services/autopilot/mavlink/message_table.hpp"

#include <algorithm>
#include <array>

#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::mavlink {
namespace {

template <Message M>
constexpr MessageInfo info_of() {
    constexpr auto& layout = MessageTraits<M>::layout;
    return MessageInfo{M::kId,        M::kName,    layout.crc_extra,          layout.base_length,
                       layout.length, layout.wire, layout.wire_index_by_decl, true};
}

constexpr auto kMessages = [] {
    std::array table{
#define AIRSEG_MAVLINK_MESSAGE(id_, NAME_, Type_) info_of<Type_>(),
#define AIRSEG_MAVLINK_FIELD(type_, name_)
#define AIRSEG_MAVLINK_ARRAY(type_, name_, length_)
#define AIRSEG_MAVLINK_VERSION_FIELD(name_)
#define AIRSEG_MAVLINK_EXTENSIONS()
#define AIRSEG_MAVLINK_END()
#include "services/autopilot/mavlink/messages.def"
    };
    std::sort(table.begin(), table.end(),
              [](const MessageInfo& a, const MessageInfo& b) { return a.id < b.id; });
    return table;
}();

constexpr bool ids_are_unique() {
    for (std::size_t i = 1; i < kMessages.size(); ++i) {
        if (kMessages[i - 1].id == kMessages[i].id) {
            return false;
        }
    }
    return true;
}
static_assert(ids_are_unique(), "a message id is declared twice in messages.def");

}  // namespace

const FieldInfo* MessageInfo::find_field(std::string_view field_name) const {
    const auto it =
        std::find_if(fields.begin(), fields.end(), [&](const FieldInfo& f) { return f.name == field_name; });
    return it == fields.end() ? nullptr : &*it;
}

std::span<const MessageInfo> all_messages() {
    return kMessages;
}

const MessageInfo* find_message(std::uint32_t id) {
    const auto it = std::lower_bound(kMessages.begin(), kMessages.end(), id,
                                     [](const MessageInfo& m, std::uint32_t value) { return m.id < value; });
    return it != kMessages.end() && it->id == id ? &*it : nullptr;
}

const MessageInfo* find_message(std::string_view name) {
    const auto it = std::find_if(kMessages.begin(), kMessages.end(),
                                 [&](const MessageInfo& m) { return m.name == name; });
    return it == kMessages.end() ? nullptr : &*it;
}

}  // namespace airseg::mavlink
