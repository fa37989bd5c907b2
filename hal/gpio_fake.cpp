#include "hal/gpio_fake.hpp"

#include <deque>

namespace airseg::hal {

struct FakeGpio::LineState {
    std::string chip;
    unsigned offset = 0;
    std::string name;
    bool value = false;
    bool requested = false;
    GpioDirection direction = GpioDirection::Input;
    std::deque<Change> history;

    void record(TimePoint at, bool v) {
        value = v;
        history.push_back({at, v});
        if (history.size() > kMaxHistory) {
            history.pop_front();
        }
    }
};

namespace {

class FakeLine final : public GpioLine {
  public:
    FakeLine(std::shared_ptr<FakeGpio::LineState> state, std::shared_ptr<std::mutex> mutex,
             const Clock& clock, std::string name)
        : state_(std::move(state)), mutex_(std::move(mutex)), clock_(clock), name_(std::move(name)) {}
    ~FakeLine() override {
        std::lock_guard lock(*mutex_);
        state_->requested = false;
    }
    FakeLine(const FakeLine&) = delete;
    FakeLine& operator=(const FakeLine&) = delete;

    std::error_code set(bool active) override {
        std::lock_guard lock(*mutex_);
        if (state_->direction != GpioDirection::Output) {
            return std::make_error_code(std::errc::operation_not_permitted);  // as the kernel refuses
        }
        state_->record(clock_.now(), active);
        return {};
    }

    bool get() const override {
        std::lock_guard lock(*mutex_);
        return state_->value;
    }

    const std::string& name() const override { return name_; }

  private:
    std::shared_ptr<FakeGpio::LineState> state_;
    std::shared_ptr<std::mutex> mutex_;
    const Clock& clock_;
    std::string name_;
};

}  // namespace

FakeGpio::FakeGpio(const Clock& clock) : clock_(clock), mutex_(std::make_shared<std::mutex>()) {}
FakeGpio::~FakeGpio() = default;

void FakeGpio::add_line(const std::string& chip, unsigned offset, const std::string& name) {
    std::lock_guard lock(*mutex_);
    auto state = std::make_shared<LineState>();
    state->chip = chip;
    state->offset = offset;
    state->name = name;
    lines_[chip + ":" + std::to_string(offset)] = std::move(state);
}

std::shared_ptr<FakeGpio::LineState> FakeGpio::find(const std::string& line) const {
    if (auto it = lines_.find(line); it != lines_.end()) {
        return it->second;
    }
    for (const auto& [key, state] : lines_) {
        if (!state->name.empty() && state->name == line) {
            return state;
        }
    }
    return nullptr;
}

GpioRequestResult FakeGpio::request(const GpioLineRequest& request) {
    GpioRequestResult result;
    const std::string where = "gpio[" + request.describe() + "]: ";
    if (auto errors = GpioLineRequest::validate(request); !errors.empty()) {
        result.error = std::make_error_code(std::errc::invalid_argument);
        result.message = errors.front();
        return result;
    }
    std::lock_guard lock(*mutex_);
    auto state = request.line_name.empty() ? find(request.chip + ":" + std::to_string(request.offset))
                                           : find(request.line_name);
    if (!state) {
        result.error = std::make_error_code(std::errc::no_such_file_or_directory);
        result.message = where + "no such line";
        return result;
    }
    if (state->requested) {
        result.error = std::make_error_code(std::errc::device_or_resource_busy);
        result.message = where + "line already requested";
        return result;
    }
    state->requested = true;
    state->direction = request.direction;
    if (request.direction == GpioDirection::Output) {
        state->record(clock_.now(), request.initial_value);
    }
    result.line =
        std::make_shared<FakeLine>(state, mutex_, clock_, state->chip + ":" + std::to_string(state->offset));
    return result;
}

std::vector<FakeGpio::Change> FakeGpio::history(const std::string& line) const {
    std::lock_guard lock(*mutex_);
    auto state = find(line);
    return state ? std::vector<Change>(state->history.begin(), state->history.end()) : std::vector<Change>{};
}

bool FakeGpio::value(const std::string& line) const {
    std::lock_guard lock(*mutex_);
    auto state = find(line);
    return state && state->value;
}

bool FakeGpio::is_requested(const std::string& line) const {
    std::lock_guard lock(*mutex_);
    auto state = find(line);
    return state && state->requested;
}

void FakeGpio::drive_input(const std::string& line, bool value) {
    std::lock_guard lock(*mutex_);
    if (auto state = find(line)) {
        state->record(clock_.now(), value);
    }
}

}  // namespace airseg::hal
