#include "services/common/port_keeper.hpp"

#include <spdlog/spdlog.h>

#include <cerrno>

namespace airseg {

std::string describe_open_failure(const hal::OpenResult& result, const std::string& path) {
    if (result.error == std::error_code(ENOENT, std::system_category())) {
        return "no " + path;
    }
    return result.message.empty() ? path + ": " + result.error.message() : result.message;
}

PortKeeper::PortKeeper(Strand strand, PortKeeperConfig config, Handlers handlers)
    : strand_(strand),
      config_(std::move(config)),
      handlers_(std::move(handlers)),
      port_(strand),
      retry_timer_(strand),
      backoff_(config_.reconnect_min) {}

void PortKeeper::start() {
    running_ = true;
    do_open();
}

void PortKeeper::stop() {
    running_ = false;
    retry_timer_.cancel();
    port_.close();
}

void PortKeeper::retry_now() {
    if (running_ && !port_.is_open()) {
        retry_timer_.cancel();
        backoff_ = config_.reconnect_min;
        do_open();
    }
}

void PortKeeper::reopen_at(unsigned baud) {
    config_.serial.baud = baud;
    if (!running_ || !port_.is_open()) {
        return;
    }
    spdlog::info("port[{}]: switching to {} baud", config_.serial.path, baud);
    port_.close();
    const bool counted = was_open_;
    was_open_ = false;  // the same device, opened again on purpose: not a reconnect
    do_open();
    was_open_ = was_open_ || counted;
}

void PortKeeper::do_open() {
    if (!running_) {
        return;
    }
    const auto& path = config_.serial.path;
    auto result = port_.open(config_.serial);
    if (!result.ok()) {
        const auto reason = describe_open_failure(result, path);
        if (reason != last_error_) {
            spdlog::warn("port[{}]: {}; retrying with backoff", path, reason);
        }
        went_down(reason);
        schedule_retry();
        return;
    }
    for (const auto& w : result.warnings) {
        spdlog::warn("port[{}]: {}", path, w);
    }
    spdlog::info("port[{}]: open at {} baud", path, config_.serial.baud);
    if (was_open_) {
        ++reconnects_;
    }
    was_open_ = true;
    last_error_.clear();
    backoff_ = config_.reconnect_min;
    port_.start_reading(
        [this](std::span<const std::uint8_t> bytes) {
            if (handlers_.on_bytes) {
                handlers_.on_bytes(bytes);
            }
        },
        [this, path](std::error_code ec, const std::string& what) {
            const auto reason = ec == hal::HalError::Unplugged ? path + " unplugged" : what;
            spdlog::warn("port[{}]: {}", path, reason);
            went_down(reason);
            schedule_retry();
        });
    if (handlers_.on_open) {
        handlers_.on_open();
    }
}

void PortKeeper::went_down(std::string reason) {
    last_error_ = std::move(reason);
    if (handlers_.on_down) {
        handlers_.on_down(last_error_);
    }
}

void PortKeeper::schedule_retry() {
    if (!running_) {
        return;
    }
    retry_timer_.expires_after(backoff_);
    backoff_ = std::min(backoff_ * 2, config_.reconnect_max);
    retry_timer_.async_wait([this](boost::system::error_code ec) {
        if (!ec) {
            do_open();
        }
    });
}

}  // namespace airseg
