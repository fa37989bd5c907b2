#include "hal/led_blinker.hpp"

#include <spdlog/spdlog.h>

namespace airseg::hal {

class LedBlinker::Impl : public std::enable_shared_from_this<Impl> {
  public:
    Impl(Executor executor, std::shared_ptr<GpioLine> line) : timer_(executor), line_(std::move(line)) {}

    void set_pattern(LedPattern pattern) {
        pattern_ = pattern;
        ++epoch_;
        timer_.cancel();
        start_ = std::chrono::steady_clock::now();
        update(epoch_);
    }

    void stop() {
        ++epoch_;
        timer_.cancel();
        apply(false);
    }

    LedPattern pattern() const { return pattern_; }

  private:
    void update(std::uint64_t epoch) {
        const Duration elapsed = std::chrono::steady_clock::now() - start_;
        apply(led_level(pattern_, elapsed));
        const Duration next = next_led_change(pattern_, elapsed);
        if (next == Duration::max()) {
            return;
        }
        timer_.expires_at(start_ + next);
        timer_.async_wait([self = shared_from_this(), epoch](boost::system::error_code ec) {
            if (!ec && epoch == self->epoch_) {
                self->update(epoch);
            }
        });
    }

    void apply(bool level) {
        if (level == level_ && known_) {
            return;
        }
        if (auto ec = line_->set(level)) {
            // Report once per failure streak; a dead LED must not flood the journal.
            if (known_ || !failed_) {
                spdlog::warn("led[{}]: cannot drive line: {}", line_->name(), ec.message());
            }
            failed_ = true;
            known_ = false;
            return;
        }
        failed_ = false;
        level_ = level;
        known_ = true;
    }

    boost::asio::steady_timer timer_;
    std::shared_ptr<GpioLine> line_;
    LedPattern pattern_ = LedPattern::Off;
    TimePoint start_{};
    std::uint64_t epoch_ = 0;
    bool level_ = false;
    bool known_ = false;
    bool failed_ = false;
};

LedBlinker::LedBlinker(Executor executor, std::shared_ptr<GpioLine> line)
    : impl_(std::make_shared<Impl>(std::move(executor), std::move(line))) {}
LedBlinker::~LedBlinker() {
    impl_->stop();
}
void LedBlinker::set_pattern(LedPattern pattern) {
    impl_->set_pattern(pattern);
}
LedPattern LedBlinker::pattern() const {
    return impl_->pattern();
}

}  // namespace airseg::hal
