#include "services/groundlink/link/key_file.hpp"

#include <fmt/format.h>

#include <cctype>
#include <cerrno>
#include <system_error>

#include "base/file_text.hpp"

namespace airseg::groundlink {

namespace {

/// The cause in the operator's words. Permission denied is the usual one on a vehicle: the key was
/// copied as root, and the daemon runs as user airseg.
std::string cannot_read(const std::string& path, int error) {
    if (error == EACCES || error == EPERM) {
        return fmt::format(
            "key file {}: permission denied: the user airsegd runs as cannot read it (the service runs as "
            "airseg: chown airseg {})",
            path, path);
    }
    return fmt::format("key file {}: cannot read it: {}", path, std::generic_category().message(error));
}

}  // namespace

KeyFileResult read_key_file(const std::string& path) {
    KeyFileResult out;
    // A key is 32 bytes, or 64 hexadecimal characters with some whitespace: a few KiB is plenty.
    const auto file = read_file_text(path, kMaxSmallFileBytes);
    if (!file.ok()) {
        out.error = file.errno_value != 0 ? cannot_read(path, file.errno_value)
                                          : fmt::format("key file {}: {}", path, file.error);
        return out;
    }
    const std::string& content = file.text;
    if ((file.mode & 077) != 0) {
        out.error =
            fmt::format("key file {} has mode {:04o}; it must be readable by its owner only (chmod 600 {})",
                        path, file.mode & 07777, path);
        return out;
    }
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
