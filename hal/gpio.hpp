#pragma once
// GPIO lines (autopilot reset, status LED) behind a small interface, so logic runs on a fake where no chip
// exists. Backends: gpio_libgpiod.hpp (the kernel's character device), gpio_fake.hpp (tests).
#include <memory>
#include <string>
#include <system_error>
#include <vector>

namespace airseg::hal {

enum class GpioDirection { Input, Output };

/// Which line to take and how. Address a line either by chip + offset or by its name (searched on every
/// chip).
struct GpioLineRequest {
    std::string chip;       ///< chip name, path or label: "gpiochip0", "/dev/gpiochip0" (yaml: chip)
    unsigned offset = 0;    ///< line offset on `chip` (yaml: offset)
    std::string line_name;  ///< or: line name from the device tree, e.g. "STATUS_LED" (yaml: line)
    GpioDirection direction = GpioDirection::Output;
    bool initial_value = false;  ///< logical level an output starts at (after active_low) (yaml: initial)
    bool active_low = false;     ///< the line is active when electrically low (yaml: active_low)
    std::string consumer = "airsegd";  ///< label the kernel shows for the requested line

    /// Every problem found, naming the field; empty when usable.
    static std::vector<std::string> validate(const GpioLineRequest& request);
    /// "gpiochip0:17" or "line \"STATUS_LED\"", for messages and logs.
    std::string describe() const;
};

/// One requested line, held until the object is destroyed. Values are logical (active_low already applied).
class GpioLine {
  public:
    virtual ~GpioLine() = default;
    /// Drives an output; returns the OS error if the kernel refused.
    virtual std::error_code set(bool active) = 0;
    /// Reads the line (an output reads back its driven level). A failed read logs and returns false.
    virtual bool get() const = 0;
    /// Where the line is, e.g. "gpiochip0:17", for log lines.
    virtual const std::string& name() const = 0;
};

struct GpioRequestResult {
    std::shared_ptr<GpioLine> line;  ///< null on failure
    std::error_code error;
    std::string message;  ///< names the line and what went wrong

    bool ok() const { return line != nullptr; }
};

/// Hands out lines; one object per backend.
class GpioFactory {
  public:
    virtual ~GpioFactory() = default;
    virtual GpioRequestResult request(const GpioLineRequest& request) = 0;
};

}  // namespace airseg::hal
