#pragma once
// ArduPilot's packed parameter file, @PARAM/param.pck of its MAVLink FTP server (libraries/AP_Filesystem,
// README.md "The @PARAM VFS"): a little-endian header (magic 0x671B, num_params, total_params), then one
// block per parameter: a byte of type (low nibble: AP_Param type INT8 1, INT16 2, INT32 3, FLOAT 4) and
// flags (high nibble), a byte of common_len (low nibble: name bytes shared with the previous name, 0..15)
// and name_len (high nibble: the bytes that follow, less one), those name bytes, and the value
// (little-endian, its type's size). Zero bytes pad so that no block crosses a read-size boundary: a block
// fetched again after a loss then never splits a value.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tools/apmsim/param_table.hpp"

namespace airseg::apmsim {

inline constexpr std::uint16_t kParamPackMagic = 0x671B;

/// The parameters `start` .. `start + count` of `table` (count 0: to the end), packed for reads of
/// `block_size` bytes (at least 32).
std::vector<std::uint8_t> pack_params(const ParamTable& table, std::size_t block_size, std::size_t start = 0,
                                      std::size_t count = 0);

struct UnpackedParam {
    std::string name;
    ParamType type = ParamType::Real32;
    float value = 0;
};
struct UnpackedParams {
    std::uint16_t total = 0;  // total_params of the header
    std::vector<UnpackedParam> params;
};
/// What a ground station reads from the file: nothing when it is not a packed parameter file (bad magic, a
/// block cut short, an unknown type, a name longer than 16 bytes, fewer blocks than num_params).
std::optional<UnpackedParams> unpack_params(std::span<const std::uint8_t> file);

}  // namespace airseg::apmsim
