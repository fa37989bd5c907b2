#include "services/groundlink/link/link_driver.hpp"

namespace airseg::groundlink {

LinkDriver::LinkDriver(Strand strand, TransportConfig config, Handlers handlers, WakeSharing* wakes)
    : core_(std::move(config), SteadyClock::now()),
      handlers_(std::move(handlers)),
      timer_(std::move(strand), wakes) {}

void LinkDriver::set_writer(std::size_t path, Writer writer) {
    if (path < writers_.size()) {
        writers_[path] = std::move(writer);
        pump();
    }
}

void LinkDriver::handle_bytes(std::size_t path, std::span<const std::uint8_t> bytes) {
    if (stopped_) {
        return;
    }
    core_.handle_bytes(path, bytes, SteadyClock::now());
    pump();
}

SendResult LinkDriver::send_safe(std::uint8_t priority, std::span<const std::uint8_t> msg) {
    const auto r = core_.send_safe(priority, msg, SteadyClock::now());
    pump();
    return r;
}

SendResult LinkDriver::send_fast(std::uint8_t priority, std::uint16_t topic,
                                 std::span<const std::uint8_t> msg) {
    const auto r = core_.send_fast(priority, topic, msg, SteadyClock::now());
    pump();
    return r;
}

void LinkDriver::stop() {
    stopped_ = true;
    timer_.cancel();
    for (auto& w : writers_) {
        w = nullptr;
    }
}

void LinkDriver::pump() {
    if (stopped_) {
        return;
    }
    // Handlers may send (an answer to a command), which pumps again: finish this round first, then loop.
    if (pumping_) {
        pump_again_ = true;
        return;
    }
    pumping_ = true;
    do {
        pump_again_ = false;
        const TimePoint now = SteadyClock::now();
        for (std::size_t p = 0; p < core_.config().paths && p < writers_.size(); ++p) {
            if (!writers_[p]) {
                // No port on this path (missing, or between reopen attempts): its frames go nowhere, like a
                // radio that is off. Not taking them would leave the core's send deadline in the past and
                // the timer firing in a loop.
                while (core_.poll_transmit(p, now)) {
                    ++write_refusals_;
                }
                continue;
            }
            while (auto frame = core_.poll_transmit(p, now)) {
                if (!writers_[p](std::move(*frame))) {
                    ++write_refusals_;  // the frame is lost as if on the air; Safe traffic is resent
                    break;
                }
            }
        }
        while (auto message = core_.poll_message()) {
            if (handlers_.on_message) {
                handlers_.on_message(std::move(*message));
            }
        }
        while (auto event = core_.poll_event()) {
            if (handlers_.on_event) {
                handlers_.on_event(*event);
            }
        }
    } while (pump_again_ && !stopped_);
    pumping_ = false;
    arm_timer();
}

void LinkDriver::arm_timer() {
    if (stopped_) {
        return;
    }
    timer_.arm(core_.poll_timeout(), [this] {
        if (stopped_) {
            return;
        }
        core_.handle_timeout(SteadyClock::now());
        pump();
    });
}

}  // namespace airseg::groundlink
