#include "tools/apmsim/param_pack.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace airseg::apmsim {

namespace {

/// AP_Param's own type numbers, as the file carries them.
std::uint8_t ap_type(ParamType t) {
    switch (t) {
        case ParamType::Int8:
            return 1;
        case ParamType::Int16:
            return 2;
        case ParamType::Int32:
            return 3;
        case ParamType::Real32:
            break;
    }
    return 4;
}

std::optional<ParamType> from_ap_type(std::uint8_t t) {
    switch (t) {
        case 1:
            return ParamType::Int8;
        case 2:
            return ParamType::Int16;
        case 3:
            return ParamType::Int32;
        case 4:
            return ParamType::Real32;
        default:
            return std::nullopt;
    }
}

std::size_t value_size(std::uint8_t ap) {
    return ap == 1 ? 1 : ap == 2 ? 2 : 4;
}

void put_le(std::vector<std::uint8_t>& out, std::uint32_t v, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
        out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    }
}

std::uint32_t value_bits(const Param& p) {
    if (p.type == ParamType::Real32) {
        std::uint32_t bits = 0;
        std::memcpy(&bits, &p.value, sizeof bits);
        return bits;
    }
    return static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(p.value)));
}

}  // namespace

std::vector<std::uint8_t> pack_params(const ParamTable& table, std::size_t block_size, std::size_t start,
                                      std::size_t count) {
    block_size = std::max<std::size_t>(block_size, 32);
    const std::size_t first = std::min(start, table.size());
    const std::size_t last = count == 0 ? table.size() : std::min(table.size(), first + count);
    std::vector<std::uint8_t> out;
    put_le(out, kParamPackMagic, 2);
    put_le(out, static_cast<std::uint32_t>(last - first), 2);
    put_le(out, static_cast<std::uint32_t>(table.size()), 2);
    std::string previous;
    for (std::size_t i = first; i < last; ++i) {
        const Param& p = table.at(i);
        const std::string name = p.name.substr(0, 16);
        std::size_t common = 0;
        while (common < 15 && common < previous.size() && common + 1 < name.size() &&
               previous[common] == name[common]) {
            ++common;
        }
        const std::size_t rest = name.size() - common;  // 1..16
        const std::uint8_t type = ap_type(p.type);
        const std::size_t block = 2 + rest + value_size(type);
        const std::size_t used = out.size() % block_size;
        if (used + block > block_size) {
            out.resize(out.size() + (block_size - used), 0);
        }
        out.push_back(type);  // flags 0: no default value follows
        out.push_back(static_cast<std::uint8_t>(common | (rest - 1) << 4));
        out.insert(out.end(), name.begin() + static_cast<std::ptrdiff_t>(common), name.end());
        put_le(out, value_bits(p), value_size(type));
        previous = name;
    }
    return out;
}

std::optional<UnpackedParams> unpack_params(std::span<const std::uint8_t> file) {
    if (file.size() < 6 || (file[0] | file[1] << 8) != kParamPackMagic) {
        return std::nullopt;
    }
    const std::size_t num = static_cast<std::size_t>(file[2] | file[3] << 8);
    UnpackedParams out;
    out.total = static_cast<std::uint16_t>(file[4] | file[5] << 8);
    std::size_t at = 6;
    std::string previous;
    while (out.params.size() < num) {
        while (at < file.size() && file[at] == 0) {
            ++at;  // padding before a block
        }
        if (at + 2 > file.size()) {
            return std::nullopt;
        }
        const auto type = from_ap_type(file[at] & 0x0F);
        const std::size_t flags = file[at] >> 4;
        const std::size_t common = file[at + 1] & 0x0F;
        const std::size_t rest = (file[at + 1] >> 4) + 1;
        if (!type || common > previous.size() || common + rest > 16) {
            return std::nullopt;
        }
        const std::size_t size = value_size(file[at] & 0x0F);
        const std::size_t values = (flags & 1) != 0 ? 2 : 1;  // bit 0: a default value follows
        if (at + 2 + rest + size * values > file.size()) {
            return std::nullopt;
        }
        std::string name = previous.substr(0, common);
        name.append(reinterpret_cast<const char*>(file.data()) + at + 2, rest);
        at += 2 + rest;
        std::uint32_t bits = 0;
        for (std::size_t i = 0; i < size; ++i) {
            bits |= std::uint32_t{file[at + i]} << (8 * i);
        }
        at += size * values;
        float value = 0;
        switch (*type) {
            case ParamType::Int8:
                value = static_cast<float>(static_cast<std::int8_t>(bits));
                break;
            case ParamType::Int16:
                value = static_cast<float>(static_cast<std::int16_t>(bits));
                break;
            case ParamType::Int32:
                value = static_cast<float>(static_cast<std::int32_t>(bits));
                break;
            case ParamType::Real32:
                std::memcpy(&value, &bits, sizeof value);
                break;
        }
        out.params.push_back({name, *type, value});
        previous = std::move(name);
    }
    return out;
}

}  // namespace airseg::apmsim
