#pragma once
// Driver: the ArduPilot Rover driver behind the neutral autopilot interface, sans-IO.
//
// Connection sequence (Phase): on_port_open() -> WaitBoot (with reset_on_open the open rebooted the
// autopilot: bootloader noise is ignored and heartbeats must reach STANDBY/ACTIVE within boot_timeout;
// without it the first running heartbeat will do) -> Params (stream rates requested, parameter table
// downloaded) -> Mission (mission downloaded; slot 0 is home) -> ApplyParams (configured parameters written
// where they differ, each read back) -> Ready (Ready event with the seconds since the port's open; the
// status's ready_s keeps the figure of the first READY after the open). A failed step is retried after
// kRetryPause; last_error() says why the driver is not READY. Every start of Params counts as a sync.
//
// Baud probing (more than one configured rate): when no valid frame from the autopilot's system id arrives
// within baud_probe of the open, the driver asks for the next rate (SwitchBaud), in turn; the service reopens
// the port and calls on_port_reopened(). The first rate that yields such a frame is kept.
//
// Afterwards it keeps: telemetry; the vehicle state derived from each heartbeat (mode changes made by the RC
// pilot or the autopilot itself are published as External ModeChanged events); requested state changes,
// confirmed by the heartbeat, retried, refused or timed out (never dropped), a change to WAYPOINT_NAVIGATION
// on a board whose heartbeat says it is disarmed going on, with autopilot.arming auto, to arm it
// (ArmControl: done once armed, refused with the board's "Arm:"/"PreArm:" reason); mission operations through
// MissionClient; parameters through ParamClient; RC override from joystick input; waypoint-reached events
// from MISSION_ITEM_REACHED or the "Reached waypoint #N" text; after every entry into AUTO the mission slot
// the board was at (AutoEntryCheck: 2.x firmware restarts at item 1); the speed of the mission item being
// driven to (its MissionItem::speed: MAV_CMD_DO_CHANGE_SPEED, set again after every entry into AUTO, or the
// parameter the board drives AUTO at on a board without the command: CRUISE_SPEED on APM 2.x, WP_SPEED on
// current Rover; its own value restored at the plan's end); link DOWN after heartbeat_timeout of silence
// (judged once the input waiting in the port has been read: a stall of the daemon itself is not the
// autopilot's silence); unexpected reboots (time_boot_ms going back and running on from there, or a
// heartbeat gap ended by a heartbeat saying BOOT/CALIBRATING/INITIALISING; never a text: LinkWatch) trigger a
// resync of parameters and mission and an AutopilotRebooted event; an autopilot silent for
// unresponsive_timeout while its port is open makes the driver ask for a reset pulse (at most
// max_reset_pulses times until it is READY again). The link's timers and reboot evidence are LinkWatch's, a
// requested mode change from request to outcome is
// ModeControl's; the driver feeds them and acts on what they report (events, frames, port actions).
//
// Contract (the service, on its strand): on_port_open/on_port_closed/on_reset_pulsed for the port; every byte
// read to handle_bytes(); handle_timeout(now) when poll_timeout() is due; requests any time. After each call
// drain poll_transmit() (one frame per call, write in order), poll_event() and poll_action().
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/ardupilot/arm_control.hpp"
#include "services/autopilot/ardupilot/auto_entry_check.hpp"
#include "services/autopilot/ardupilot/link_watch.hpp"
#include "services/autopilot/ardupilot/mission_client.hpp"
#include "services/autopilot/ardupilot/mode_control.hpp"
#include "services/autopilot/ardupilot/outbox.hpp"
#include "services/autopilot/ardupilot/param_client.hpp"
#include "services/autopilot/ardupilot/rc_override.hpp"
#include "services/autopilot/autopilot.hpp"
#include "services/autopilot/autopilot_config.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::autopilot::ardupilot {

/// The service should reconfigure the port to this baud rate (baud probing).
struct SwitchBaud {
    unsigned baud = 0;
};
/// The service should pulse the autopilot's reset line, then call on_reset_pulsed().
struct PulseReset {
    unsigned attempt = 0;
};
using DriverAction = std::variant<SwitchBaud, PulseReset>;

enum class Phase : std::uint8_t { Closed, WaitBoot, Params, Mission, ApplyParams, Ready };
const char* to_string(Phase p);

class Driver {
  public:
    /// Called with every frame written to or read from the autopilot (for the flight recorder).
    using FrameTap = std::function<void(bool outgoing, std::span<const std::uint8_t> frame)>;
    static constexpr Duration kRetryPause = seconds(5);

    explicit Driver(AutopilotConfig config);

    // --- port lifecycle ---
    void on_port_open(TimePoint now);
    void on_port_closed(const std::string& reason, TimePoint now);
    /// The port was reopened at another baud rate after a SwitchBaud: the byte stream starts afresh, the
    /// connection sequence and its timers go on.
    void on_port_reopened(TimePoint now);
    void on_reset_pulsed(TimePoint now);

    // --- sans-IO plumbing ---
    void handle_bytes(std::span<const std::uint8_t> bytes, TimePoint now);
    /// `input_waiting`: the port holds bytes not read yet; an overdue heartbeat is not judged on them.
    void handle_timeout(TimePoint now, bool input_waiting = false);
    TimePoint poll_timeout() const;
    std::optional<std::vector<std::uint8_t>> poll_transmit();
    std::optional<Event> poll_event();
    std::optional<DriverAction> poll_action();
    void set_frame_tap(FrameTap tap) { tap_ = std::move(tap); }

    // --- requests (each ends with exactly one RequestDone event carrying the returned id) ---
    std::uint32_t request_state(VehicleState state, TimePoint now);
    /// Replaces the mission with `items` at slots 1..n; slot 0 (home) is kept.
    std::uint32_t upload_mission(std::vector<MissionItem> items, TimePoint now);
    std::uint32_t write_items(std::uint16_t first_slot, std::vector<MissionItem> items, TimePoint now);
    std::uint32_t download_mission(TimePoint now);
    std::uint32_t set_current(std::uint16_t slot, TimePoint now);
    std::uint32_t clear_mission(TimePoint now);
    std::uint32_t get_param(const std::string& name, TimePoint now);
    std::uint32_t set_param(const std::string& name, double value, TimePoint now);
    /// Ground joystick, -1..1 each; drives only in MANUAL_NAVIGATION and only while fresh.
    void joystick(double steering, double throttle, TimePoint now);
    /// Clears the failsafe MANUAL latch (the operator's explicit reset).
    void operator_reset(TimePoint now);

    // --- views ---
    Phase phase() const { return phase_; }
    const Telemetry& telemetry() const { return telemetry_; }
    AutopilotStatus status() const;
    /// Slots 1..n of the mission as last uploaded or downloaded.
    const std::vector<MissionItem>& mission() const { return mission_; }
    const ParamClient& params() const { return params_; }
    const MissionClient& mission_client() const { return missions_; }
    const RcOverride& rc_override() const { return rc_; }
    const mavlink::ParserStats& parser_stats() const { return parser_.stats(); }
    unsigned current_baud() const { return link_.baud(); }
    const std::string& last_error() const { return last_error_; }
    const AutoEntryCheck& auto_entry_check() const { return auto_check_; }
    /// The speed the board last confirmed for the leg it drives (m/s), if any was set.
    std::optional<double> commanded_speed() const { return speed_set_; }
    /// The heartbeat's SAFETY_ARMED; empty before the first heartbeat of this connection.
    std::optional<bool> armed() const { return armed_seen_ ? std::optional<bool>(armed_) : std::nullopt; }
    const ArmControl& arm_control() const { return arming_; }
    /// Speed changes the board confirmed, ever.
    unsigned speed_changes() const { return speed_changes_; }
    /// True when speeds go by a parameter (the board lacks MAV_CMD_DO_CHANGE_SPEED): speed_param().
    bool speed_by_param() const { return speed_by_param_; }
    /// The parameter the board drives AUTO at: WP_SPEED when it has one (current Rover), else CRUISE_SPEED.
    const char* speed_param() const;
    /// True when Stop items go as waypoints and the driver holds the vehicle on arrival.
    bool stops_as_jumps() const { return stop_as_jump_; }
    bool link_up() const { return link_.up(); }
    bool ready() const { return phase_ == Phase::Ready && link_.up(); }

  private:
    struct SpeedRequest {
        double value = 0.0;
        unsigned attempt = 0;
        TimePoint deadline = kNever;  // the command's answer; kNever while a parameter write runs
        std::uint32_t param_op = 0;   // ParamClient id of a CRUISE_SPEED write
    };
    struct PendingOp {
        std::uint32_t id = 0;  // the requester's id; 0 for the driver's own (sequence) operations
        RequestKind kind = RequestKind::UploadMission;
        std::vector<MissionItem> items;  // what an upload/partial write puts in the cache on success
        std::uint16_t first = 1;
        std::uint16_t stored_through = 0;  // partial write: the slots before this one are told on board
    };

    // driver.cpp: lifecycle, sequencing, requests
    void enter(Phase p, TimePoint now);
    void request_streams();
    void start_apply_params(TimePoint now);
    void sequence_failed(const std::string& why, TimePoint now);
    void drain_clients(TimePoint now);
    void on_mission_done(MissionCompletion c, TimePoint now);
    bool retry_with_stops_as_jumps(const PendingOp& op, const MissionCompletion& c, TimePoint now);
    void on_param_done(ParamCompletion c, TimePoint now);
    void cancel_everything(const std::string& why, TimePoint now);
    void done(std::uint32_t id, RequestKind kind, RequestResult result, std::string detail = {},
              std::optional<bool> stop_ends_mission = std::nullopt);
    std::uint32_t reject_if_not_ready(RequestKind kind);
    void send_mode(std::uint32_t mode);
    void send_due_modes();
    void finish_mode(ModeOutcome o, TimePoint now);
    void state_done(std::uint32_t id, RequestResult result, std::string detail);
    static bool arms_for(VehicleState target);
    bool needs_arming() const;
    void start_arming(std::uint32_t id, TimePoint now);
    void send_due_arming();
    void update_state(TimePoint now, bool requested);
    void emit(Event e) { events_.push_back(std::move(e)); }
    void flush_rc(TimePoint now);
    void send_gcs_heartbeat_if_due(TimePoint now);

    // driver_frames.cpp: what comes from the autopilot
    void on_frame(const mavlink::Frame& f, TimePoint now);
    void on_heartbeat(const mavlink::Heartbeat& hb, TimePoint now);
    void on_position(const char* message, std::int32_t lat_e7, std::int32_t lon_e7, std::int32_t alt_mm);
    void invalidate_position(std::string why);
    void take_float(const char* where, float value, double& field);
    void refuse_value(std::string why);
    void on_statustext(const mavlink::Statustext& t, TimePoint now);
    void on_time_boot(std::uint32_t time_boot_ms, TimePoint now);
    void on_command_ack(const mavlink::CommandAck& ack, TimePoint now);
    void on_reached(std::uint16_t seq, TimePoint now);
    void reboot_detected(const std::string& evidence, TimePoint now);
    /// Reboots are looked for once the autopilot has booted (not while a boot is waited for).
    bool watching_for_reboots() const { return phase_ != Phase::WaitBoot && phase_ != Phase::Closed; }
    void link_lost(Duration silent, const std::string& detail, TimePoint now);
    void tap_incoming(const mavlink::Frame& f);
    void on_mission_current(std::uint16_t seq, TimePoint now);
    void report_current(std::uint16_t seq);
    std::uint16_t board_slot() const;

    // driver_speed.cpp: the speed of the leg being driven
    void update_speed(TimePoint now);
    void send_speed(double value, unsigned attempt, TimePoint now);
    void on_speed_ack(std::uint8_t result, TimePoint now);
    void speed_timeout(TimePoint now);
    bool on_speed_param_done(const ParamCompletion& c, TimePoint now);
    void forget_speed();
    void on_auto_entered();
    void on_params_known();
    void restore_board_speed(TimePoint now);

    AutopilotConfig config_;
    Outbox out_;
    mavlink::Parser parser_;
    MissionClient missions_;
    ParamClient params_;
    RcOverride rc_;
    LinkWatch link_;
    ModeControl modes_;
    ArmControl arming_;
    FrameTap tap_;

    Phase phase_ = Phase::Closed;
    TimePoint sequence_start_{};         // the port's open
    TimePoint phase_deadline_ = kNever;  // boot timeout, or the pause before retrying a failed step
    bool retry_pending_ = false;
    std::string last_error_;
    std::optional<double> ready_s_;

    TimePoint next_gcs_heartbeat_ = kNever;
    // How late our heartbeat may go when no input comes to carry it: ArduPilot's GCS failsafe waits seconds.
    static constexpr Duration kGcsHeartbeatSlack = std::chrono::milliseconds(500);

    // Vehicle.
    std::optional<std::uint32_t> mode_;
    std::uint8_t system_status_ = 0;
    bool override_active_ = false;
    bool armed_ = false;       // the last heartbeat's SAFETY_ARMED
    bool armed_seen_ = false;  // a heartbeat came since the port opened or the board rebooted
    bool failsafe_latched_ = false;
    VehicleState state_ = VehicleState::Unknown;
    std::string mode_name_;
    Telemetry telemetry_;
    std::optional<std::uint8_t> gps_fix_type_;  // the last GPS_RAW_INT's; none before one comes
    std::uint64_t refused_values_ = 0;          // NaN, infinite or out-of-range values not taken
    std::string refused_value_;                 // the last of them, e.g. "ATTITUDE.roll is NaN"
    std::optional<std::pair<std::uint16_t, TimePoint>> last_reached_;
    std::uint16_t reported_current_ = 0;  // the mission slot last reported (MissionCurrentChanged)
    bool current_reached_ = false;        // the board reported reported_current_ reached since
    AutoEntryCheck auto_check_;
    bool stop_as_jump_ = false;  // the board lacks NAV_LOITER_UNLIM: Stop items go as DO_JUMP past the end
    std::optional<double> speed_set_;
    std::optional<double> board_speed_;    // speed_param() before the first change: restored at the end
    std::optional<double> speed_refused_;  // not asked again until AUTO is entered again or it changes
    std::optional<SpeedRequest> speed_request_;
    bool speed_by_param_ = false;
    unsigned speed_changes_ = 0;
    unsigned reboots_ = 0;
    unsigned syncs_ = 0;  // starts of the parameter and mission download (Phase::Params)

    // Mission and parameters.
    std::vector<MissionItem> mission_;
    std::optional<mavlink::MissionItemInt> home_slot_;
    std::map<std::uint32_t, PendingOp> mission_ops_;  // by MissionClient id
    std::map<std::uint32_t, PendingOp> param_ops_;    // by ParamClient id
    std::uint32_t sequence_fetch_ = 0;
    std::uint32_t sequence_download_ = 0;
    std::map<std::uint32_t, std::string> sequence_sets_;  // ParamClient id -> parameter
    std::vector<std::string> apply_failures_;
    std::uint32_t next_id_ = 1;

    std::deque<Event> events_;
    std::deque<DriverAction> actions_;
};

}  // namespace airseg::autopilot::ardupilot
