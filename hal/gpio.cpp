#include "hal/gpio.hpp"

namespace airseg::hal {

std::vector<std::string> GpioLineRequest::validate(const GpioLineRequest& request) {
    std::vector<std::string> errors;
    if (request.chip.empty() && request.line_name.empty()) {
        errors.emplace_back("gpio: give either chip + offset or a line name");
    }
    if (!request.chip.empty() && !request.line_name.empty()) {
        errors.push_back("gpio: both chip \"" + request.chip + "\" and line name \"" + request.line_name +
                         "\" given; use one");
    }
    if (request.consumer.empty()) {
        errors.push_back("gpio[" + request.describe() + "]: consumer label is empty");
    }
    return errors;
}

std::string GpioLineRequest::describe() const {
    if (!line_name.empty()) {
        return "line \"" + line_name + "\"";
    }
    return chip + ":" + std::to_string(offset);
}

}  // namespace airseg::hal
