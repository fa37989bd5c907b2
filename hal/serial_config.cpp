#include "hal/serial_config.hpp"

#include <algorithm>
#include <array>

namespace airseg::hal {
namespace {

constexpr std::array<unsigned, 9> kSupportedBauds = {9600,   19200,  38400,  57600, 115200,
                                                     230400, 460800, 500000, 921600};

std::string list_bauds() {
    std::string out;
    for (unsigned b : kSupportedBauds) {
        if (!out.empty()) {
            out += ", ";
        }
        out += std::to_string(b);
    }
    return out;
}

}  // namespace

std::span<const unsigned> supported_bauds() noexcept {
    return kSupportedBauds;
}

bool is_supported_baud(unsigned baud) noexcept {
    return std::find(kSupportedBauds.begin(), kSupportedBauds.end(), baud) != kSupportedBauds.end();
}

std::vector<std::string> SerialConfig::validate(const SerialConfig& config) {
    std::vector<std::string> errors;
    if (config.path.empty()) {
        errors.emplace_back("serial: device path is empty");
    }
    if (!is_supported_baud(config.baud)) {
        errors.push_back("serial[" + config.path + "]: baud " + std::to_string(config.baud) +
                         " is not supported (supported: " + list_bauds() + ")");
    }
    if (config.rtscts && config.rts_on_open.has_value()) {
        errors.push_back("serial[" + config.path +
                         "]: rts cannot be driven by hand while rtscts flow control is on");
    }
    if (config.max_queued_bytes == 0) {
        errors.push_back("serial[" + config.path + "]: max_queued_bytes must be greater than 0");
    }
    return errors;
}

}  // namespace airseg::hal
