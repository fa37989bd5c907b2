#pragma once
// Derives a message's wire layout and CRC_EXTRA from its declaration, at compile time, by the rules of the
// MAVLink specification (the same ones pymavlink's generator applies):
//  - base fields (those before <extensions/>) are sorted by element size, largest first; the sort is stable,
//    so fields of equal size keep their XML order; arrays sort by their element size;
//  - extension fields follow in XML order, unsorted;
//  - CRC_EXTRA is the X.25 CRC of "NAME " followed, for each base field in wire order, by "type " and
//    "name " and, for an array, one byte holding its length; the 16-bit result is folded to 8 bits as
//    (crc & 0xFF) ^ (crc >> 8). Extension fields never enter CRC_EXTRA.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "services/autopilot/mavlink/crc.hpp"
#include "services/autopilot/mavlink/field.hpp"
#include "services/autopilot/mavlink/frame.hpp"

namespace airseg::mavlink {

template <std::size_t N>
struct MessageLayout {
    std::array<FieldInfo, N> wire{};                   // fields in wire order
    std::array<std::uint8_t, N> offset_by_decl{};      // byte offset of the i-th declared field
    std::array<std::uint8_t, N> wire_index_by_decl{};  // index in `wire` of the i-th declared field
    std::uint8_t crc_extra = 0;
    std::uint8_t base_length = 0;  // bytes of the base fields: the MAVLink 1 payload length
    std::uint8_t length = 0;       // bytes of all fields, extensions included
};

/// Number of real fields in a declaration (the extensions marker is not a field).
constexpr std::size_t field_count(std::span<const FieldDecl> decls) {
    std::size_t n = 0;
    for (const FieldDecl& d : decls) {
        n += d.is_extensions_marker ? 0 : 1;
    }
    return n;
}

constexpr std::uint8_t crc_extra_of(std::string_view message_name, std::span<const FieldInfo> wire_fields) {
    Crc16 crc;
    crc.add(message_name);
    crc.add(" ");
    for (const FieldInfo& f : wire_fields) {
        if (f.extension) {
            continue;
        }
        crc.add(type_name(f.type));
        crc.add(" ");
        crc.add(f.name);
        crc.add(" ");
        if (f.array_length != 0) {
            crc.add(f.array_length);
        }
    }
    return static_cast<std::uint8_t>((crc.value() & 0xFF) ^ (crc.value() >> 8));
}

/// What lay_out() derives besides the field placement.
struct LayoutSummary {
    std::uint8_t crc_extra = 0;
    std::uint8_t base_length = 0;
    std::uint8_t length = 0;
};

/// Lays out one message: `wire` (one entry per real field of `decls`) receives the fields in wire order with
/// their offsets, `wire_index_by_decl` the wire position of each declared field. Shared by the typed messages
/// (make_layout) and the dialect table (dialect_table.cpp), so both follow one reading of the rules.
constexpr LayoutSummary lay_out(std::string_view message_name, std::span<const FieldDecl> decls,
                                std::span<FieldInfo> wire, std::span<std::uint8_t> wire_index_by_decl) {
    if (wire.size() != field_count(decls) || wire_index_by_decl.size() != wire.size()) {
        throw "declaration does not hold the expected number of fields";
    }
    // wire_index_by_decl first holds, for each wire slot, the declared index of its field (sorted along).
    std::size_t count = 0;
    std::size_t base_count = 0;
    bool in_extensions = false;
    for (const FieldDecl& d : decls) {
        if (d.is_extensions_marker) {
            in_extensions = true;
            continue;
        }
        wire[count] = FieldInfo{d.name, d.type, d.array_length, 0, in_extensions};
        wire_index_by_decl[count] = static_cast<std::uint8_t>(count);
        ++count;
        base_count += in_extensions ? 0 : 1;
    }
    // Stable insertion sort of the base fields, largest element size first.
    for (std::size_t i = 1; i < base_count; ++i) {
        const FieldInfo moving = wire[i];
        const std::uint8_t moving_decl = wire_index_by_decl[i];
        std::size_t j = i;
        while (j > 0 && type_size(wire[j - 1].type) < type_size(moving.type)) {
            wire[j] = wire[j - 1];
            wire_index_by_decl[j] = wire_index_by_decl[j - 1];
            --j;
        }
        wire[j] = moving;
        wire_index_by_decl[j] = moving_decl;
    }
    std::array<std::uint8_t, kMaxPayload> decl_by_wire{};  // a message has at most 255 fields of a byte
    LayoutSummary summary{};
    std::size_t offset = 0;
    for (std::size_t i = 0; i < count; ++i) {
        wire[i].offset = static_cast<std::uint8_t>(offset);
        offset += wire[i].size();
        if (offset > kMaxPayload) {
            throw "message payload longer than 255 bytes";
        }
        if (i + 1 == base_count) {
            summary.base_length = static_cast<std::uint8_t>(offset);
        }
        decl_by_wire[i] = wire_index_by_decl[i];
    }
    for (std::size_t i = 0; i < count; ++i) {
        wire_index_by_decl[decl_by_wire[i]] = static_cast<std::uint8_t>(i);
    }
    summary.length = static_cast<std::uint8_t>(offset);
    summary.crc_extra = crc_extra_of(message_name, wire.first(count));
    return summary;
}

template <std::size_t N>
constexpr MessageLayout<N> make_layout(std::string_view message_name, std::span<const FieldDecl> decls) {
    MessageLayout<N> layout{};
    const LayoutSummary summary = lay_out(message_name, decls, layout.wire, layout.wire_index_by_decl);
    for (std::size_t d = 0; d < N; ++d) {
        layout.offset_by_decl[d] = layout.wire[layout.wire_index_by_decl[d]].offset;
    }
    layout.crc_extra = summary.crc_extra;
    layout.base_length = summary.base_length;
    layout.length = summary.length;
    return layout;
}

}  // namespace airseg::mavlink
