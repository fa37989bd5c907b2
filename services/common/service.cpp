#include "services/common/service.hpp"

#include <spdlog/spdlog.h>

namespace airseg {

Service::Service(std::string name, ServiceContext& ctx)
    : ctx_(ctx), name_(std::move(name)), strand_(asio::make_strand(ctx.io)), tick_timer_(strand_, ctx.wakes) {
    ctx_.health.add(name_, SteadyClock::now());
}

Service::~Service() = default;

void Service::start(std::function<void()> started) {
    asio::dispatch(strand_, [this, started = std::move(started)] {
        running_ = true;
        on_start();
        do_tick();
        if (started) {
            started();
        }
    });
}

void Service::stop(std::function<void()> stopped) {
    {
        std::lock_guard lock(hang_mutex_);
        hang_released_ = true;
    }
    hang_cv_.notify_all();
    asio::dispatch(strand_, [this, stopped = std::move(stopped)] {
        if (running_) {
            running_ = false;
            tick_timer_.cancel();
            on_stop();
        }
        if (stopped) {
            stopped();
        }
    });
}

void Service::inject_hang() {
    asio::post(strand_, [this] {
        spdlog::warn("{}: test hang injected: blocking this service's strand", name_);
        std::unique_lock lock(hang_mutex_);
        hang_cv_.wait(lock, [this] { return hang_released_; });
    });
}

void Service::set_health(Health health, std::string error) {
    const std::string shown = error;
    if (ctx_.health.set(name_, health, std::move(error))) {
        if (health == Health::Up) {
            spdlog::info("{}: up", name_);
        } else {
            spdlog::warn("{}: {}{}{}", name_, to_string(health), shown.empty() ? "" : ": ", shown);
        }
    }
}

void Service::do_tick() {
    if (!running_) {
        return;
    }
    const TimePoint now = SteadyClock::now();
    ctx_.health.progress(name_, now);
    on_tick(now);
    // Up to a quarter interval late, to share a wake-up: the watchdog allows two intervals (app.cpp).
    tick_timer_.arm(next_on_grid(now, ctx_.progress_interval), ctx_.progress_interval / 4,
                    [this] { do_tick(); });
}

}  // namespace airseg
