#include "daemon/autopilot_status_led.hpp"

#include <spdlog/spdlog.h>

#include "services/groundlink/link_state.hpp"

namespace airseg::daemon {

StatusLedDriver::StatusLedDriver(Bus& bus, Strand strand, std::shared_ptr<hal::GpioLine> line)
    : line_(std::move(line)), led_(SteadyClock::now()), timer_(strand) {
    autopilot_sub_ =
        bus.subscribe<autopilot::AutopilotStatus>(strand, [this](const autopilot::AutopilotStatus& s) {
            led_.autopilot(s, SteadyClock::now());
            show();
        });
    groundlink_sub_ = bus.subscribe<groundlink::LinkState>(strand, [this](const groundlink::LinkState& s) {
        led_.ground_link(s.up, SteadyClock::now());
        show();
    });
    asio::dispatch(strand, [this] { show(); });
}

StatusLedDriver::~StatusLedDriver() {
    timer_.cancel();
    line_->set(false);
}

void StatusLedDriver::show() {
    const TimePoint now = SteadyClock::now();
    const bool level = led_.level(now);
    if (level != level_ || armed_ == kNever) {
        level_ = level;
        if (auto ec = line_->set(level); ec && !failed_) {
            failed_ = true;
            spdlog::warn("status led {}: {}", line_->name(), ec.message());
        }
    }
    const TimePoint next = led_.next_change(now);
    if (next == armed_) {
        return;
    }
    armed_ = next;
    if (next == kNever) {
        timer_.cancel();
        return;
    }
    timer_.expires_at(next);
    timer_.async_wait([this](const boost::system::error_code& ec) {
        if (ec) {
            return;  // re-armed, or stopping
        }
        armed_ = kNever;
        show();
    });
}

}  // namespace airseg::daemon
