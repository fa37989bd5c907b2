#pragma once
// LinkWatch: what the serial link to the autopilot is doing, sans-IO.
//
// Link up on the first heartbeat, down when a heartbeat is overdue by heartbeat_timeout; the verdict waits
// kReadGrace more, so that a daemon that was itself stopped or starved (its timer and its port ready at
// once, the frames of the pause still in the port) reads what came before it judges (longer while even that
// wake comes late, or while the port still holds bytes not read: at most heartbeat_timeout more). Baud
// probing (more than one configured rate): when no frame from the autopilot's system id arrives within
// baud_probe of the open, the next rate is due, in turn; the first that yields such a frame is kept. An
// autopilot silent (link down) for unresponsive_timeout while its port is open is due a reset pulse, at most
// max_reset_pulses until the budget is refilled (the driver does so on READY).
//
// Reboot evidence, and only this: the autopilot's time_boot_ms went back by more than kClockBackSlack and
// ran on from the new value for kClockConfirm (the old clock not seen again meanwhile), or a heartbeat gap of
// kBootGap or more ended by a heartbeat of a booting autopilot, or a heartbeat in the boot mode after one in
// a running mode (Rover is in INITIALISING only while it boots). A text is never evidence (ArduPilot sends
// its banner on every parameter list request). At most one reboot is declared per kRebootSpacing; evidence
// within that is held and declared when it ends (one declaration for all of it).
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
    /// An overdue heartbeat is judged this long later: time for the input waiting in the port to be read.
    static constexpr Duration kReadGrace = milliseconds(250);
    /// A wake this late past its deadline means the daemon was not running: the grace starts again.
    static constexpr Duration kLateWake = milliseconds(250);
    /// A heartbeat gap this long (ArduPilot beats at 1 Hz) ended by a booting heartbeat is a reboot.
    static constexpr Duration kBootGap = milliseconds(1500);
    /// time_boot_ms going back by less than this is jitter between messages, not a restart.
    static constexpr Duration kClockBackSlack = seconds(1);
    /// How long a clock that went back must run on (the old one not seen again) before it counts.
    static constexpr Duration kClockConfirm = milliseconds(1500);
    /// At most one reboot declared per this long.
    static constexpr Duration kRebootSpacing = seconds(10);

    /// What handle_timeout() found due.
    struct Due {
        std::optional<Duration> lost;       // the link went down after this long without a heartbeat
        std::string lost_detail;            // with `lost`: what the port carried meanwhile (silence_text)
        std::optional<unsigned> baud;       // reconfigure the port to this rate
        std::optional<unsigned> pulse;      // unresponsive: ask for reset pulse number N
        bool pulses_exhausted = false;      // unresponsive, and the pulse budget is spent
        std::optional<std::string> reboot;  // reboot evidence held back by kRebootSpacing, declared now
    };
    /// What a heartbeat told.
    struct HeartbeatSeen {
        bool came_up = false;               // the link came up with it
        std::optional<std::string> reboot;  // a reboot declared now, with its evidence
    };

    explicit LinkWatch(LinkWatchConfig config);

    void on_port_open(TimePoint now);
    /// Returns true when the link was up (it is down now).
    bool on_port_closed();
    void on_reset_pulsed(TimePoint now);
    /// A valid frame from the autopilot's system id: ends baud probing.
    void on_frame();
    /// Bytes read from the port (before parsing), for what a link-down verdict says the port carried.
    void on_bytes(std::size_t n, TimePoint now);
    /// What the port carried since the last heartbeat: nothing (a silent board, or a cut line), or bytes and
    /// the autopilot's frames without a heartbeat among them (a board that stopped beating, or a line that
    /// garbles), with how long ago the last bytes came (a reader that stopped reading).
    std::string silence_text(TimePoint now) const;
    /// `booting`: the heartbeat says the autopilot is starting up; `watching`: reboots are looked for (not
    /// while a boot is being waited for); `boot_mode_after`, when not empty: the heartbeat's mode is the one
    /// the firmware holds only while it boots (Rover's INITIALISING), and the last heartbeat's was this one.
    HeartbeatSeen on_heartbeat(TimePoint now, bool booting, bool watching,
                               std::string_view boot_mode_after = {});
    /// Feeds the autopilot's time_boot_ms; with `watching`, returns a reboot declared now.
    std::optional<std::string> on_time_boot(std::uint32_t time_boot_ms, TimePoint now, bool watching);
    /// The clock of the boot being waited for starts again; evidence held back is dropped.
    void forget_boot_clock();

    /// `input_waiting`: the port holds bytes not read yet (the I/O side asks the kernel). An overdue
    /// heartbeat's verdict then waits another kReadGrace, within heartbeat_timeout: a reader starved for
    /// CPU drains a backlog of seconds slower than one grace, and the heartbeat may be in it.
    Due handle_timeout(TimePoint now, bool input_waiting = false);
    TimePoint poll_timeout() const;

    /// Takes one reset pulse from the budget: its number, or nothing when the budget is spent.
    std::optional<unsigned> take_pulse();
    void refill_pulses() { pulses_ = 0; }

    bool up() const { return up_; }
    bool port_open() const { return port_open_; }
    unsigned baud() const { return config_.bauds[baud_index_]; }
    /// Reset pulses asked for, ever.
    unsigned reset_pulses() const { return reset_pulses_; }
    /// Times the link went down for want of heartbeats, ever.
    unsigned link_losses() const { return link_losses_; }
    /// Verdicts on an overdue heartbeat put off because the port still held unread bytes, ever.
    unsigned verdicts_deferred() const { return verdicts_deferred_; }
    /// Reboot evidence that came within kRebootSpacing of a declared reboot, ever.
    unsigned reboots_held() const { return reboots_held_; }

  private:
    struct ClockSample {
        std::uint32_t ms = 0;
        TimePoint at{};
    };
    std::optional<std::string> declare(std::string evidence, TimePoint now);

    LinkWatchConfig config_;
    bool port_open_ = false;
    bool up_ = false;
    TimePoint last_heartbeat_{};
    std::size_t bytes_since_heartbeat_ = 0;
    std::size_t frames_since_heartbeat_ = 0;
    TimePoint last_bytes_at_{};
    TimePoint heartbeat_due_ = kNever;        // the next look at an overdue heartbeat
    std::optional<TimePoint> overdue_since_;  // the first look that found it overdue
    TimePoint quiet_since_{};                 // reference for the unresponsive timer
    bool heard_frame_ = false;
    std::size_t baud_index_ = 0;
    TimePoint baud_deadline_ = kNever;
    unsigned pulses_ = 0;
    unsigned reset_pulses_ = 0;
    unsigned link_losses_ = 0;
    unsigned verdicts_deferred_ = 0;
    // Reboot evidence.
    std::optional<ClockSample> clock_;          // the autopilot's clock as trusted
    std::optional<ClockSample> restart_first_;  // where it went back to, while that is being confirmed
    ClockSample restart_last_;                  // its latest sample since
    TimePoint next_reboot_allowed_{};
    std::optional<std::string> held_reboot_;
    unsigned reboots_held_ = 0;
};

}  // namespace airseg::autopilot::ardupilot
