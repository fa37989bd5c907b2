#pragma once
// LinkWatch: what the serial link to the autopilot is doing, sans-IO.
//
// Link up on the first heartbeat, down after heartbeat_timeout without one. Baud probing (more than one
// configured rate): when no frame from the autopilot's system id arrives within baud_probe of the open, the
// next rate is due, in turn; the first that yields such a frame is kept. An autopilot silent (link down) for
// unresponsive_timeout while its port is open is due a reset pulse, at most max_reset_pulses until the budget
// is refilled (the driver does so on READY). Reboot evidence: time_boot_ms running slower than our clock, and
// boot banners within kGapWindow of the link coming back.
//
// What to do about it (events, port actions, the connection sequence) is the Driver's: it feeds the port
// lifecycle, frames and heartbeats in, calls handle_timeout(now) when poll_timeout() is due and acts on the
// returned Due.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "base/time.hpp"

namespace airseg::autopilot::ardupilot {

struct LinkWatchConfig {
    std::vector<unsigned> bauds = {115200};  // tried in turn; empty means 115200
    Duration baud_probe = seconds(3);
    bool reset_on_open = true;  // the open reboots the autopilot: silence is expected for boot_timeout
    Duration boot_timeout = seconds(30);
    Duration heartbeat_timeout = seconds(3);
    Duration unresponsive_timeout = seconds(20);
    unsigned max_reset_pulses = 3;
};

class LinkWatch {
  public:
    /// Boot banners this long after the link came back mean the autopilot rebooted in the gap.
    static constexpr Duration kGapWindow = seconds(10);

    /// What handle_timeout() found due.
    struct Due {
        std::optional<Duration> lost;   // the link went down after this long without a heartbeat
        std::optional<unsigned> baud;   // reconfigure the port to this rate
        std::optional<unsigned> pulse;  // unresponsive: ask for reset pulse number N
        bool pulses_exhausted = false;  // unresponsive, and the pulse budget is spent
    };

    explicit LinkWatch(LinkWatchConfig config);

    void on_port_open(TimePoint now);
    /// Returns true when the link was up (it is down now).
    bool on_port_closed();
    void on_reset_pulsed(TimePoint now);
    /// A valid frame from the autopilot's system id: ends baud probing.
    void on_frame();
    /// Returns true when the link came up with this heartbeat.
    bool on_heartbeat(TimePoint now);
    /// `lowered` is a STATUSTEXT in lower case; true when it is a boot banner within the gap window.
    bool reboot_banner(std::string_view lowered, TimePoint now) const;
    /// Feeds the autopilot's time_boot_ms; with `watching` (not waiting for a boot) returns the reboot
    /// evidence when the autopilot's clock ran slower than ours since the last sample.
    std::optional<std::string> on_time_boot(std::uint32_t time_boot_ms, TimePoint now, bool watching);
    /// The clock of the boot being waited for starts again.
    void forget_boot_clock() { time_boot_.reset(); }

    Due handle_timeout(TimePoint now);
    TimePoint poll_timeout() const;

    /// Takes one reset pulse from the budget: its number, or nothing when the budget is spent.
    std::optional<unsigned> take_pulse();
    void refill_pulses() { pulses_ = 0; }

    bool up() const { return up_; }
    bool port_open() const { return port_open_; }
    unsigned baud() const { return config_.bauds[baud_index_]; }
    /// Reset pulses asked for, ever.
    unsigned reset_pulses() const { return reset_pulses_; }

  private:
    LinkWatchConfig config_;
    bool port_open_ = false;
    bool up_ = false;
    TimePoint last_heartbeat_{};
    TimePoint quiet_since_{};  // reference for the unresponsive timer
    bool heard_frame_ = false;
    std::size_t baud_index_ = 0;
    TimePoint baud_deadline_ = kNever;
    unsigned pulses_ = 0;
    unsigned reset_pulses_ = 0;
    TimePoint gap_window_end_{};
    std::optional<std::pair<std::uint32_t, TimePoint>> time_boot_;
};

}  // namespace airseg::autopilot::ardupilot
