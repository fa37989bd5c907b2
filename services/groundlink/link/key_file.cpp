#include "services/groundlink/link/key_file.hpp"

#include <fmt/format.h>
#include <sys/stat.h>

#include <cctype>
#include <fstream>
#include <iterator>

namespace airseg::groundlink {

KeyFileResult read_key_file(const std::string& path) {
    KeyFileResult out;
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        out.error = fmt::format("key file {}: cannot read it", path);
        return out;
    }
    if ((st.st_mode & 077) != 0) {
        out.error =
            fmt::format("key file {} has mode {:04o}; it must be readable by its owner only (chmod 600 {})",
                        path, st.st_mode & 07777, path);
        return out;
    }
    std::ifstream in(path, std::ios::binary);
    const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::array<std::uint8_t, 32> key{};
    if (content.size() == key.size()) {
        for (std::size_t i = 0; i < key.size(); ++i) {
            key[i] = static_cast<std::uint8_t>(content[i]);
        }
        out.key = key;
        return out;
    }
    std::string hex;
    for (char c : content) {
        if (!std::isspace(static_cast<unsigned char>(c))) {
            hex += c;
        }
    }
    if (hex.size() != 64 || hex.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos) {
        out.error = fmt::format("key file {}: expected 32 raw bytes or 64 hexadecimal characters", path);
        return out;
    }
    for (std::size_t i = 0; i < key.size(); ++i) {
        key[i] = static_cast<std::uint8_t>(std::stoi(hex.substr(2 * i, 2), nullptr, 16));
    }
    out.key = key;
    return out;
}

}  // namespace airseg::groundlink
