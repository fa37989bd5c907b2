// The dialect catalogue (message_table.hpp): dialect.def laid out once, at compile time, by the rules of
// layout.hpp. Kept apart from message_table.cpp so that the typed structs are not compiled again for it.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <utility>

#include "services/autopilot/mavlink/layout.hpp"
#include "services/autopilot/mavlink/message_table.hpp"

namespace airseg::mavlink {
// Named apart from message_table.cpp's internals: a unity build compiles both in one translation unit.
namespace dialect_table {
namespace {

// Every declaration of the dialect, message after message, each in XML order with its extensions marker.
constexpr FieldDecl kDecls[] = {
#define AIRSEG_MAVLINK_DIALECT_MESSAGE(id_, name_)
#define AIRSEG_MAVLINK_DIALECT_FIELD(type_, name_, length_) \
    FieldDecl{name_, FieldTypeOf<type_>::value, length_, false},
#define AIRSEG_MAVLINK_DIALECT_EXTENSIONS() FieldDecl{"", FieldType::Uint8, 0, true},
#define AIRSEG_MAVLINK_DIALECT_END()
#include "services/autopilot/mavlink/dialect.def"
};

struct Head {
    std::uint32_t id;
    std::string_view name;
    std::size_t decl_count;  // entries in kDecls, the extensions marker included
};
constexpr Head kHeads[] = {
#define AIRSEG_MAVLINK_DIALECT_MESSAGE(id_, name_) \
    Head {                                         \
        id_, name_, 0
#define AIRSEG_MAVLINK_DIALECT_FIELD(type_, name_, length_) +1
#define AIRSEG_MAVLINK_DIALECT_EXTENSIONS() +1
#define AIRSEG_MAVLINK_DIALECT_END() \
    }                                \
    ,
#include "services/autopilot/mavlink/dialect.def"
};
constexpr std::size_t kMessageCount = std::size(kHeads);

constexpr std::uint32_t kTypedIds[] = {
#define AIRSEG_MAVLINK_MESSAGE(id_, NAME_, Type_) id_,
#define AIRSEG_MAVLINK_FIELD(type_, name_)
#define AIRSEG_MAVLINK_ARRAY(type_, name_, length_)
#define AIRSEG_MAVLINK_VERSION_FIELD(name_)
#define AIRSEG_MAVLINK_EXTENSIONS()
#define AIRSEG_MAVLINK_END()
#include "services/autopilot/mavlink/messages.def"
};

// Where each message's declarations start in kDecls.
constexpr std::array<std::size_t, kMessageCount> kFirstDecl = [] {
    std::array<std::size_t, kMessageCount> first{};
    std::size_t decl = 0;
    for (std::size_t m = 0; m < kMessageCount; ++m) {
        first[m] = decl;
        decl += kHeads[m].decl_count;
    }
    if (decl != std::size(kDecls)) {
        throw "dialect.def is not read whole";
    }
    return first;
}();

template <std::size_t M>
constexpr std::span<const FieldDecl> decls_of() {
    return std::span(kDecls).subspan(kFirstDecl[M], kHeads[M].decl_count);
}

template <std::size_t N>
struct LaidMessage {
    std::array<FieldInfo, N> wire{};
    std::array<std::uint8_t, N> wire_index_by_decl{};
    LayoutSummary summary{};
};

// One variable per message, so that each is its own constant evaluation: laying out the whole dialect in one
// would exceed the evaluation budget of a compiler (clang's 1,048,576 steps) long before it exceeds GCC's.
template <std::size_t M>
constexpr auto kLaid = [] {
    LaidMessage<field_count(decls_of<M>())> laid{};
    laid.summary = lay_out(kHeads[M].name, decls_of<M>(), laid.wire, laid.wire_index_by_decl);
    return laid;
}();

constexpr bool is_typed(std::uint32_t id) {
    return std::find(std::begin(kTypedIds), std::end(kTypedIds), id) != std::end(kTypedIds);
}

template <std::size_t... M>
constexpr std::array<MessageInfo, kMessageCount> make_infos(std::index_sequence<M...>) {
    return {MessageInfo{kHeads[M].id, kHeads[M].name, kLaid<M>.summary.crc_extra,
                        kLaid<M>.summary.base_length, kLaid<M>.summary.length, std::span(kLaid<M>.wire),
                        std::span(kLaid<M>.wire_index_by_decl), is_typed(kHeads[M].id)}...};
}
constexpr auto kDialect = make_infos(std::make_index_sequence<kMessageCount>{});

constexpr bool ordered_by_unique_id() {
    for (std::size_t i = 1; i < kDialect.size(); ++i) {
        if (kDialect[i - 1].id >= kDialect[i].id) {
            return false;
        }
    }
    return true;
}
static_assert(ordered_by_unique_id(), "dialect.def must list each message id once, in ascending order");

}  // namespace
}  // namespace dialect_table

std::span<const MessageInfo> dialect_messages() {
    return dialect_table::kDialect;
}

const MessageInfo* find_dialect_message(std::uint32_t id) {
    const auto it = std::lower_bound(dialect_table::kDialect.begin(), dialect_table::kDialect.end(), id,
                                     [](const MessageInfo& m, std::uint32_t value) { return m.id < value; });
    return it != dialect_table::kDialect.end() && it->id == id ? &*it : nullptr;
}

const MessageInfo* find_dialect_message(std::string_view name) {
    const auto it = std::find_if(dialect_table::kDialect.begin(), dialect_table::kDialect.end(),
                                 [&](const MessageInfo& m) { return m.name == name; });
    return it == dialect_table::kDialect.end() ? nullptr : &*it;
}

}  // namespace airseg::mavlink
