#include "hal/error.hpp"

#include <ostream>

namespace airseg::hal {
namespace {

class HalCategory final : public std::error_category {
  public:
    const char* name() const noexcept override { return "airseg.hal"; }
    std::string message(int value) const override {
        switch (static_cast<HalError>(value)) {
            case HalError::Unplugged:
                return "device unplugged";
            case HalError::ReadFailed:
                return "read failed";
            case HalError::WriteFailed:
                return "write failed";
            case HalError::InvalidConfig:
                return "invalid configuration";
            case HalError::NotATerminal:
                return "not a terminal";
            case HalError::PathOccupied:
                return "path occupied by a file that is not a symlink";
        }
        return "unknown hal error " + std::to_string(value);
    }
};

}  // namespace

const std::error_category& hal_category() noexcept {
    static const HalCategory category;
    return category;
}

std::error_code make_error_code(HalError e) noexcept {
    return {static_cast<int>(e), hal_category()};
}

OpenResult invalid_config(const std::vector<std::string>& errors) {
    OpenResult result;
    result.error = make_error_code(HalError::InvalidConfig);
    for (const auto& e : errors) {
        result.message += result.message.empty() ? e : "; " + e;
    }
    return result;
}

const char* to_string(WriteResult r) noexcept {
    switch (r) {
        case WriteResult::Queued:
            return "queued";
        case WriteResult::NotOpen:
            return "not open";
        case WriteResult::QueueFull:
            return "queue full";
        case WriteResult::NoPeer:
            return "no peer";
        case WriteResult::TooLarge:
            return "too large";
    }
    return "unknown";
}

std::ostream& operator<<(std::ostream& os, WriteResult r) {
    return os << to_string(r);
}

std::ostream& operator<<(std::ostream& os, HalError e) {
    return os << make_error_code(e).message();
}

}  // namespace airseg::hal
