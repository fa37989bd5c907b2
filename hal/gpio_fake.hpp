#pragma once
// An in-memory GPIO backend for tests: declared lines, a history of every level driven, inputs set by the
// test.
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "hal/clock.hpp"
#include "hal/gpio.hpp"

namespace airseg::hal {

/// Lines must be declared with add_line() before they can be requested, as on a board whose chips are fixed.
/// Requests follow the kernel's rules: unknown chip, offset or name → ENOENT; a line already held → EBUSY.
/// Every level a line takes (including the initial level of an output) is recorded with clock.now().
/// Thread-safe, so a test may inspect it while an io_context runs elsewhere.
class FakeGpio final : public GpioFactory {
  public:
    struct Change {
        TimePoint at;
        bool value;
    };
    /// Bound of each line's history; older entries are dropped first.
    static constexpr std::size_t kMaxHistory = 100000;

    explicit FakeGpio(const Clock& clock);
    ~FakeGpio() override;

    void add_line(const std::string& chip, unsigned offset, const std::string& name = {});

    GpioRequestResult request(const GpioLineRequest& request) override;

    /// Lines are named "chip:offset" here, or by their line name.
    std::vector<Change> history(const std::string& line) const;
    bool value(const std::string& line) const;
    bool is_requested(const std::string& line) const;
    /// Sets the level an input line reads (what the outside world drives).
    void drive_input(const std::string& line, bool value);

    struct LineState;  // shared with the handed-out lines

  private:
    std::shared_ptr<LineState> find(const std::string& line) const;

    const Clock& clock_;
    std::shared_ptr<std::mutex> mutex_;
    std::map<std::string, std::shared_ptr<LineState>> lines_;  // by "chip:offset"
};

}  // namespace airseg::hal
