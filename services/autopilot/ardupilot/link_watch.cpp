#include "services/autopilot/ardupilot/link_watch.hpp"

#include <algorithm>

namespace airseg::autopilot::ardupilot {

namespace {
constexpr Duration kClockSlack = seconds(2);  // latency jitter allowed when comparing time_boot_ms

bool is_boot_banner(std::string_view text) {
    return text.starts_with("initialising apm") || text.starts_with("init ardu") ||
           text.starts_with("ardurover") || text.starts_with("apm:rover");
}
}  // namespace

LinkWatch::LinkWatch(LinkWatchConfig config) : config_(std::move(config)) {
    if (config_.bauds.empty()) {
        config_.bauds.push_back(115200);
    }
}

void LinkWatch::on_port_open(TimePoint now) {
    port_open_ = true;
    quiet_since_ = now;
    heard_frame_ = false;
    time_boot_.reset();
    baud_deadline_ = config_.bauds.size() > 1 ? now + config_.baud_probe : kNever;
    if (config_.reset_on_open) {
        // The open rebooted the autopilot: silence is expected until the boot window has passed.
        quiet_since_ = now + config_.boot_timeout;
    }
}

bool LinkWatch::on_port_closed() {
    port_open_ = false;
    baud_deadline_ = kNever;
    return std::exchange(up_, false);
}

void LinkWatch::on_reset_pulsed(TimePoint now) {
    quiet_since_ = now;
    time_boot_.reset();
}

void LinkWatch::on_frame() {
    // Only the autopilot's own frames end baud probing: line noise at a wrong rate passes a checksum now
    // and then, but hardly ever with the right system id as well.
    heard_frame_ = true;
    baud_deadline_ = kNever;
}

bool LinkWatch::on_heartbeat(TimePoint now) {
    last_heartbeat_ = now;
    quiet_since_ = now;
    if (up_) {
        return false;
    }
    up_ = true;
    gap_window_end_ = now + kGapWindow;
    return true;
}

bool LinkWatch::reboot_banner(std::string_view lowered, TimePoint now) const {
    return is_boot_banner(lowered) && now < gap_window_end_;
}

std::optional<std::string> LinkWatch::on_time_boot(std::uint32_t time_boot_ms, TimePoint now, bool watching) {
    const auto previous = std::exchange(time_boot_, std::pair{time_boot_ms, now});
    if (!previous || !watching) {
        return std::nullopt;
    }
    const auto [before, at] = *previous;
    const auto ours = std::chrono::duration_cast<milliseconds>(now - at).count();
    const std::int64_t theirs = static_cast<std::int64_t>(time_boot_ms) - static_cast<std::int64_t>(before);
    const auto slack =
        std::chrono::duration_cast<milliseconds>(std::max(kClockSlack, config_.heartbeat_timeout));
    if (theirs + slack.count() < ours) {
        return theirs < 0 ? "time_boot_ms went back" : "time_boot_ms restarted during a silence";
    }
    return std::nullopt;
}

LinkWatch::Due LinkWatch::handle_timeout(TimePoint now) {
    Due due;
    if (up_ && now >= last_heartbeat_ + config_.heartbeat_timeout) {
        up_ = false;
        due.lost = now - last_heartbeat_;
    }
    if (port_open_ && now >= baud_deadline_ && !heard_frame_) {
        baud_index_ = (baud_index_ + 1) % config_.bauds.size();
        due.baud = config_.bauds[baud_index_];
        baud_deadline_ = now + config_.baud_probe;
        quiet_since_ = std::max(quiet_since_, now - config_.unresponsive_timeout / 2);
    }
    if (port_open_ && !up_ && now >= quiet_since_ + config_.unresponsive_timeout) {
        due.pulse = take_pulse();
        due.pulses_exhausted = !due.pulse;
        quiet_since_ = now;  // give the pulse (or the operator) time before the next one
    }
    return due;
}

TimePoint LinkWatch::poll_timeout() const {
    TimePoint t = kNever;
    if (up_) {
        t = last_heartbeat_ + config_.heartbeat_timeout;
    }
    if (port_open_) {
        if (!heard_frame_) {
            t = std::min(t, baud_deadline_);
        }
        if (!up_) {
            t = std::min(t, quiet_since_ + config_.unresponsive_timeout);
        }
    }
    return t;
}

std::optional<unsigned> LinkWatch::take_pulse() {
    if (pulses_ >= config_.max_reset_pulses) {
        return std::nullopt;
    }
    ++pulses_;
    ++reset_pulses_;
    return pulses_;
}

}  // namespace airseg::autopilot::ardupilot
