#include "hal/gpio_pulse.hpp"

namespace airseg::hal {

void pulse(const Executor& executor, std::shared_ptr<GpioLine> line, Duration width,
           std::function<void(std::error_code)> done) {
    const std::error_code first = line->set(true);
    auto timer = std::make_shared<boost::asio::steady_timer>(executor, width);
    timer->async_wait(
        [timer, line = std::move(line), first, done = std::move(done)](boost::system::error_code) {
            // Release the line even if the wait was cancelled: a reset line must never stay asserted.
            const std::error_code second = line->set(false);
            if (done) {
                done(first ? first : second);
            }
        });
}

}  // namespace airseg::hal
