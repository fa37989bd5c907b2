#pragma once
// The ground link's pre-shared key file: 32 bytes, either raw or as 64 hexadecimal characters (whitespace
// ignored). Readable by its owner only: a key file that group or others may read is refused.
#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace airseg::groundlink {

struct KeyFileResult {
    std::optional<std::array<std::uint8_t, 32>> key;
    std::string error;  // names the file and what is wrong with it
};

KeyFileResult read_key_file(const std::string& path);

}  // namespace airseg::groundlink
