#include "services/autopilot/ardupilot/link_watch.hpp"

#include <algorithm>
#include <cstdio>

namespace airseg::autopilot::ardupilot {

namespace {
/// `to` relative to `from` on the autopilot's 32-bit millisecond clock, which wraps after 49.7 days.
std::int64_t clock_step(std::uint32_t from, std::uint32_t to) {
    return static_cast<std::int32_t>(to - from);
}

std::int64_t ms_of(Duration d) {
    return std::chrono::duration_cast<milliseconds>(d).count();
}

std::string seconds_text(Duration d) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f", std::chrono::duration<double>(d).count());
    return buf;
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
    forget_boot_clock();
    baud_deadline_ = config_.bauds.size() > 1 ? now + config_.baud_probe : kNever;
    if (config_.reset_on_open) {
        // The open rebooted the autopilot: silence is expected until the boot window has passed.
        quiet_since_ = now + config_.boot_timeout;
    }
}

bool LinkWatch::on_port_closed() {
    port_open_ = false;
    baud_deadline_ = kNever;
    heartbeat_due_ = kNever;
    overdue_since_.reset();
    return std::exchange(up_, false);
}

void LinkWatch::on_reset_pulsed(TimePoint now) {
    quiet_since_ = now;
    forget_boot_clock();
}

void LinkWatch::on_frame() {
    // Only the autopilot's own frames end baud probing: line noise at a wrong rate passes a checksum now
    // and then, but hardly ever with the right system id as well.
    heard_frame_ = true;
    baud_deadline_ = kNever;
    ++frames_since_heartbeat_;
}

void LinkWatch::on_bytes(std::size_t n, TimePoint now) {
    bytes_since_heartbeat_ += n;
    last_bytes_at_ = now;
}

std::string LinkWatch::silence_text(TimePoint now) const {
    if (bytes_since_heartbeat_ == 0) {
        return "nothing read from the port since the last one";
    }
    return std::to_string(bytes_since_heartbeat_) + " bytes read since the last one, " +
           std::to_string(frames_since_heartbeat_) +
           " of the autopilot's frames among them, the last bytes " + seconds_text(now - last_bytes_at_) +
           " s ago";
}

LinkWatch::HeartbeatSeen LinkWatch::on_heartbeat(TimePoint now, bool booting, bool watching,
                                                 std::string_view boot_mode_after) {
    HeartbeatSeen seen;
    const Duration gap = now - last_heartbeat_;
    if (watching && booting && last_heartbeat_ != TimePoint{} && gap >= kBootGap) {
        seen.reboot =
            declare("a heartbeat gap of " + seconds_text(gap) + " s ended by a booting heartbeat", now);
    } else if (watching && !boot_mode_after.empty()) {
        // A boot too short for kBootGap (or its gap hidden by heartbeats read late) still shows in the mode:
        // the clock's evidence would come kClockConfirm later, while the booted board is already being
        // driven on what it kept in storage.
        seen.reboot = declare("the heartbeat's mode went from " + std::string(boot_mode_after) +
                                  " to INITIALISING, which the firmware holds only while it boots",
                              now);
    }
    last_heartbeat_ = now;
    bytes_since_heartbeat_ = 0;
    frames_since_heartbeat_ = 0;
    quiet_since_ = now;
    heartbeat_due_ = now + config_.heartbeat_timeout;
    overdue_since_.reset();
    seen.came_up = !std::exchange(up_, true);
    return seen;
}

std::optional<std::string> LinkWatch::on_time_boot(std::uint32_t time_boot_ms, TimePoint now, bool watching) {
    const ClockSample sample{time_boot_ms, now};
    const auto slack = ms_of(kClockBackSlack);
    if (!clock_ || !watching || clock_step(clock_->ms, time_boot_ms) >= -slack) {
        // The clock runs on (forward jumps included: a clock that jumps ahead restarted nothing).
        clock_ = sample;
        restart_first_.reset();
        return std::nullopt;
    }
    // Behind the clock: a restart if it runs on from here, and the old clock is not seen again, for a while.
    if (!restart_first_ || clock_step(restart_last_.ms, time_boot_ms) < -slack) {
        restart_first_ = sample;
        restart_last_ = sample;
        return std::nullopt;
    }
    restart_last_ = sample;
    if (now - restart_first_->at < kClockConfirm) {
        return std::nullopt;
    }
    const std::string evidence = "time_boot_ms went back from " + std::to_string(clock_->ms) + " to " +
                                 std::to_string(restart_first_->ms) + " ms and ran on from there";
    clock_ = sample;
    restart_first_.reset();
    return declare(evidence, now);
}

void LinkWatch::forget_boot_clock() {
    clock_.reset();
    restart_first_.reset();
    held_reboot_.reset();
}

std::optional<std::string> LinkWatch::declare(std::string evidence, TimePoint now) {
    if (now < next_reboot_allowed_) {
        ++reboots_held_;
        if (!held_reboot_) {
            held_reboot_ = std::move(evidence);
        }
        return std::nullopt;
    }
    next_reboot_allowed_ = now + kRebootSpacing;
    return evidence;
}

LinkWatch::Due LinkWatch::handle_timeout(TimePoint now, bool input_waiting) {
    Due due;
    if (up_ && now >= heartbeat_due_) {
        const bool woke_late = now - heartbeat_due_ > kLateWake;  // not awake long enough to tell
        if (!overdue_since_) {
            // Overdue: the heartbeats may be in the port, unread, if the daemon itself was not running.
            overdue_since_ = now;
            heartbeat_due_ = now + kReadGrace;
        } else if ((woke_late || input_waiting) && now - *overdue_since_ < config_.heartbeat_timeout) {
            // Even the grace ended late, or the backlog is still being read: judged once it is.
            if (!woke_late) {
                ++verdicts_deferred_;
            }
            heartbeat_due_ = now + kReadGrace;
        } else {
            up_ = false;
            ++link_losses_;
            due.lost = now - last_heartbeat_;
            due.lost_detail = silence_text(now);
            heartbeat_due_ = kNever;
            overdue_since_.reset();
        }
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
    if (held_reboot_ && now >= next_reboot_allowed_) {
        due.reboot = std::exchange(held_reboot_, std::nullopt);
        next_reboot_allowed_ = now + kRebootSpacing;
    }
    return due;
}

TimePoint LinkWatch::poll_timeout() const {
    TimePoint t = kNever;
    if (up_) {
        t = heartbeat_due_;
    }
    if (port_open_) {
        if (!heard_frame_) {
            t = std::min(t, baud_deadline_);
        }
        if (!up_) {
            t = std::min(t, quiet_since_ + config_.unresponsive_timeout);
        }
    }
    if (held_reboot_) {
        t = std::min(t, next_reboot_allowed_);
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
