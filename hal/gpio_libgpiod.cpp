#include "hal/gpio_libgpiod.hpp"

#include <gpiod.h>
#include <spdlog/spdlog.h>

#include <cerrno>

namespace airseg::hal {
namespace {

std::error_code errno_or(int fallback) {
    return {errno != 0 ? errno : fallback, std::system_category()};
}

class LibgpiodLine final : public GpioLine {
  public:
    LibgpiodLine(gpiod_chip* chip, gpiod_line* line, std::string name)
        : chip_(chip), line_(line), name_(std::move(name)) {}
    ~LibgpiodLine() override {
        gpiod_line_release(line_);
        gpiod_chip_close(chip_);
    }
    LibgpiodLine(const LibgpiodLine&) = delete;
    LibgpiodLine& operator=(const LibgpiodLine&) = delete;

    std::error_code set(bool active) override {
        errno = 0;
        if (gpiod_line_set_value(line_, active ? 1 : 0) != 0) {
            return errno_or(EIO);
        }
        return {};
    }

    bool get() const override {
        errno = 0;
        const int value = gpiod_line_get_value(line_);
        if (value < 0) {
            spdlog::warn("gpio[{}]: read failed: {}", name_, errno_or(EIO).message());
            return false;
        }
        return value != 0;
    }

    const std::string& name() const override { return name_; }

  private:
    gpiod_chip* chip_;
    gpiod_line* line_;
    std::string name_;
};

GpioRequestResult failure(std::error_code ec, std::string message) {
    GpioRequestResult result;
    result.error = ec;
    result.message = std::move(message);
    return result;
}

}  // namespace

GpioRequestResult LibgpiodFactory::request(const GpioLineRequest& request) {
    const std::string where = "gpio[" + request.describe() + "]: ";
    if (auto errors = GpioLineRequest::validate(request); !errors.empty()) {
        std::string message;
        for (const auto& e : errors) {
            message += message.empty() ? e : "; " + e;
        }
        return failure(std::make_error_code(std::errc::invalid_argument), message);
    }

    gpiod_chip* chip = nullptr;
    gpiod_line* line = nullptr;
    errno = 0;
    if (!request.line_name.empty()) {
        line = gpiod_line_find(request.line_name.c_str());
        if (line == nullptr) {
            const auto ec = errno_or(ENOENT);
            return failure(
                ec, where + (ec.value() == ENOENT ? std::string("no GPIO line with this name on any chip")
                                                  : "line search failed: " + ec.message()));
        }
        chip = gpiod_line_get_chip(line);
    } else {
        chip = gpiod_chip_open_lookup(request.chip.c_str());
        if (chip == nullptr) {
            const auto ec = errno_or(ENOENT);
            return failure(ec, where + "cannot open GPIO chip \"" + request.chip + "\": " + ec.message());
        }
        const unsigned count = gpiod_chip_num_lines(chip);
        if (request.offset >= count) {
            gpiod_chip_close(chip);
            return failure(std::make_error_code(std::errc::invalid_argument),
                           where + "offset out of range: chip has " + std::to_string(count) + " lines");
        }
        line = gpiod_chip_get_line(chip, request.offset);
        if (line == nullptr) {
            const auto ec = errno_or(EINVAL);
            gpiod_chip_close(chip);
            return failure(ec, where + "cannot get line: " + ec.message());
        }
    }

    const int flags = request.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
    errno = 0;
    const int rc = request.direction == GpioDirection::Output
                       ? gpiod_line_request_output_flags(line, request.consumer.c_str(), flags,
                                                         request.initial_value ? 1 : 0)
                       : gpiod_line_request_input_flags(line, request.consumer.c_str(), flags);
    if (rc != 0) {
        const auto ec = errno_or(EIO);
        gpiod_chip_close(chip);
        return failure(ec, where + "request failed (line in use by another consumer?): " + ec.message());
    }

    std::string name = std::string(gpiod_chip_name(chip)) + ":" + std::to_string(gpiod_line_offset(line));
    if (const char* line_name = gpiod_line_name(line); line_name != nullptr && *line_name != '\0') {
        name += std::string(" (") + line_name + ")";
    }
    GpioRequestResult result;
    result.line = std::make_shared<LibgpiodLine>(chip, line, std::move(name));
    return result;
}

}  // namespace airseg::hal
