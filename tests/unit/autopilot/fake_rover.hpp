#pragma once
// A scripted ArduPilot Rover peer for the autopilot cores' tests: bytes in, bytes out, simulated time. It
// answers the mission protocol the way ArduPilot does (re-requests an item after 1 s, gives up an upload
// after 8 s of silence, MAV_MISSION_INVALID_SEQUENCE for an item it did not ask for), serves parameters,
// changes mode on SET_MODE / MAV_CMD_DO_SET_MODE, streams heartbeats and SYSTEM_TIME, and can boot,
// reboot and stall on command.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::autopilot::testing {

namespace mav = airseg::mavlink;

// Rover custom modes.
inline constexpr std::uint32_t kManual = 0;
inline constexpr std::uint32_t kHold = 4;
inline constexpr std::uint32_t kAuto = 10;

class FakeRover {
  public:
    struct Options {
        mav::Version version = mav::Version::V2;
        bool request_int = true;  // ask for items with MISSION_REQUEST_INT (else MISSION_REQUEST)
        bool send_item_reached = true;
        Duration boot_delay = seconds(2);   // silent (bootloader) after a reset
        Duration calibration = seconds(1);  // heartbeats with MAV_STATE_CALIBRATING
        bool boot_texts = true;             // "Initialising APM" and the version banner after a boot
        std::size_t params = 40;
        std::size_t max_items = 400;
        /// Frames a position item may have; others get MAV_MISSION_UNSUPPORTED_FRAME (empty: any).
        std::set<std::uint8_t> accepted_frames{};
        bool restart_mission_on_auto = false;  // AUTO starts the mission at item 1 (APM:Rover 2.x)
        bool change_speed_command = true;      // knows MAV_CMD_DO_CHANGE_SPEED (else UNSUPPORTED)
        bool loiter_unlim = true;              // stores NAV_LOITER_UNLIM (else MAV_MISSION_UNSUPPORTED)
        bool uninit_in_hold = false;           // heartbeats say MAV_STATE_UNINIT in HOLD (APM:Rover 2.x)
        bool banner_on_param_list = false;     // the banner texts before the parameters (ArduPilot 4.x)
        bool arming_required = false;  // boots disarmed (no SAFETY_ARMED) until MAV_CMD_COMPONENT_ARM_DISARM
        std::string arm_refusal{};     // when set, arming fails: "Arm: <refusal>" after the ack FAILED
        bool arm_acks = true;          // the arm command is acknowledged (else silently ignored)
        bool current_rover_speed = false;  // WP_SPEED 2; DO_CHANGE_SPEED FAILED outside AUTO (Rover 4.x)
    };

    explicit FakeRover(Options options, TimePoint now);

    void handle_bytes(std::span<const std::uint8_t> bytes, TimePoint now);
    void handle_timeout(TimePoint now);
    TimePoint poll_timeout() const;
    std::optional<std::vector<std::uint8_t>> poll_transmit();

    /// Power cycle / reset line: silent for boot_delay, then booting heartbeats, then standby.
    void reboot(TimePoint now);
    /// Heartbeats say mode INITIALISING (16) until `until` while the clock runs on: what a board reports
    /// first after a reset, before its clock samples show the reset.
    void report_initialising(TimePoint until) { initialising_until_ = until; }
    /// No output at all (and input ignored) until `until`.
    void stall(TimePoint until) { stall_until_ = until; }
    /// The RC pilot flips the mode switch.
    void pilot_sets_mode(std::uint32_t mode, TimePoint now);
    /// The vehicle reaches mission slot `seq` (MISSION_ITEM_REACHED and/or the STATUSTEXT).
    void reach(std::uint16_t seq, TimePoint now);
    /// Another ground station asked for the parameter list: the answer (banner, parameters) goes out here
    /// too.
    void parameter_list_asked(TimePoint now);

    std::uint32_t mode() const { return mode_; }
    bool armed() const { return armed_; }
    unsigned arm_commands() const { return arm_commands_; }
    bool booted(TimePoint now) const { return now >= boot_done_; }
    const std::vector<mav::MissionItemInt>& mission() const { return mission_; }
    std::uint16_t mission_current() const { return current_; }
    std::map<std::string, float>& params() { return params_; }
    std::set<std::uint32_t>& refused_modes() { return refused_modes_; }
    std::optional<mav::RcChannelsOverride> last_override() const { return last_override_; }
    TimePoint last_override_at() const { return last_override_at_; }
    std::size_t overrides_received() const { return overrides_; }
    std::size_t param_sets() const { return param_sets_; }
    /// Speeds set by MAV_CMD_DO_CHANGE_SPEED, in order.
    const std::vector<float>& speed_commands() const { return speed_commands_; }
    /// Frames of the position items received, in order (MISSION_ITEM or MISSION_ITEM_INT).
    const std::vector<std::pair<std::uint32_t, std::uint8_t>>& item_frames() const { return item_frames_; }
    unsigned upload_aborts() const { return upload_aborts_; }
    std::uint32_t time_boot_ms(TimePoint now) const;

  private:
    template <mav::Message M>
    void send(const M& m) {
        out_.push_back(encoder_.encode(m));
    }
    void on_frame(const mav::Frame& f, TimePoint now);
    void send_heartbeat(TimePoint now);
    void send_param(std::size_t index);
    void request_item(TimePoint now);
    void send_ack(std::uint8_t type);
    void set_mode(std::uint32_t mode, TimePoint now);
    void text(std::uint8_t severity, const std::string& s);

    Options options_;
    mav::Encoder encoder_;
    mav::Parser parser_;
    std::deque<std::vector<std::uint8_t>> out_;
    std::uint8_t requester_compid_ = 191;
    TimePoint boot_start_;
    TimePoint boot_done_;
    TimePoint stall_until_{};
    TimePoint initialising_until_{};
    TimePoint next_heartbeat_;
    bool boot_texts_sent_;
    std::uint32_t mode_ = kHold;
    bool armed_ = false;
    unsigned arm_commands_ = 0;
    std::set<std::uint32_t> refused_modes_;
    std::vector<float> speed_commands_;
    std::vector<std::pair<std::uint32_t, std::uint8_t>> item_frames_;  // (message id, frame)
    std::map<std::string, float> params_;
    std::vector<std::string> param_order_;
    std::size_t param_sets_ = 0;

    std::vector<mav::MissionItemInt> mission_;
    std::uint16_t current_ = 0;
    // Upload in progress.
    bool receiving_ = false;
    std::vector<mav::MissionItemInt> incoming_;
    std::uint16_t request_i_ = 0, request_last_ = 0;
    TimePoint last_request_{}, last_receive_{};
    unsigned upload_aborts_ = 0;

    std::optional<mav::RcChannelsOverride> last_override_;
    TimePoint last_override_at_{};
    std::size_t overrides_ = 0;
};

}  // namespace airseg::autopilot::testing
