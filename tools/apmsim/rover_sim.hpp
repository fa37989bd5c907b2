#pragma once
// RoverSim: a simulated APM:Rover board, sans-IO. Bytes and simulated time go in, bytes come out; it never
// reads a clock or touches a descriptor, so tests and benchmarks can run it in-process in simulated time and
// airseg-apmsim (main.cpp) runs it on a pseudo-terminal in scaled real time.
//
// Contract (the driver's loop):
//   RoverSim sim(config, now);                 // power on: the boot sequence starts at `now`
//   sim.handle_bytes(bytes_from_gcs, now);     // whenever bytes arrive
//   sim.handle_timeout(now);                   // when now >= sim.poll_timeout()
//   write(sim.poll_transmit());                // after each of the above
//   re-arm the timer at sim.poll_timeout()     // the single earliest deadline
// Board events: port_opened(now) (the USB DTR reset), reboot(now), schedule_reboot(at), rc_pilot(mode, now),
// force_mode(mode, now) (the board changes mode itself, as a failsafe does). Time must not go backwards
// between calls.
//
// What it does: boot sequence (silent, then "Initialising APM..." and heartbeats in CALIBRATING, then
// STANDBY and "Ready to drive."), 1 Hz heartbeats with Rover custom modes, telemetry streams, parameters,
// the mission protocol (mission_server.hpp), modes and a kinematic vehicle that drives missions, RTL,
// guided targets (MISSION_ITEM in GUIDED, COMMAND_INT MAV_CMD_DO_REPOSITION) and RC overrides, TIMESYNC,
// MAVLink FTP of the packed parameter file (ftp_server.hpp), and the fault injection of Faults. Every mode
// change is recorded with its cause in mode_history(), every change of the speed the rover drives at in
// speed_log().
//
// The firmware it behaves as is RoverSimConfig::firmware (firmware_profile.hpp): modern ArduPilot Rover, or
// APMrover2 2.4x (rover2), whose receiver, mission protocol, command processor and telemetry are modelled
// on that firmware's source (legacy_parser.hpp, legacy_mission_server.hpp, rover_sim_rover2.cpp).
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/mavlink/frame.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tools/apmsim/firmware_profile.hpp"
#include "tools/apmsim/ftp_server.hpp"
#include "tools/apmsim/legacy_mission_server.hpp"
#include "tools/apmsim/legacy_parser.hpp"
#include "tools/apmsim/mission_change_detector.hpp"
#include "tools/apmsim/mission_server.hpp"
#include "tools/apmsim/mission_store.hpp"
#include "tools/apmsim/outbox.hpp"
#include "tools/apmsim/param_table.hpp"
#include "tools/apmsim/rover_mode.hpp"
#include "tools/apmsim/stream_scheduler.hpp"
#include "tools/apmsim/vehicle_model.hpp"

namespace airseg::apmsim {

/// Where a stored navigation item points.
inline GeoPoint point_of(const StoredItem& item) {
    return GeoPoint{item.lat_e7 / 1e7, item.lon_e7 / 1e7};
}

enum class ReachedStyle : std::uint8_t {
    MessageAndText,  // MISSION_ITEM_REACHED and the STATUSTEXT
    TextOnly,        // the STATUSTEXT alone, as APM:Rover 2.x firmware does
};

struct RoverSimConfig {
    /// The firmware the board runs. for_firmware() sets it together with the version, reached style and
    /// mission timers that firmware has.
    FirmwareProfile firmware = FirmwareProfile::modern();
    GeoPoint home{41.2756, 1.9866};  // a car park in Castelldefels
    float home_alt = 5.0F;           // metres above mean sea level
    Duration boot_delay = seconds(2);
    Duration calib_time = seconds(3);
    bool reset_on_open = true;  // an APM on USB reboots when the port is opened
    std::size_t mission_capacity = 150;
    ReachedStyle reached_style = ReachedStyle::MessageAndText;
    mavlink::Version version = mavlink::Version::V2;
    std::uint64_t seed = 1;
    Duration mission_rerequest = seconds(1);
    Duration mission_give_up = seconds(8);
    Duration physics_step = milliseconds(20);
    /// Wall-clock time (µs since 1970) at the simulated time passed to the constructor, for SYSTEM_TIME and
    /// GPS time stamps.
    std::uint64_t unix_time_at_start_us = 1'401'580'800'000'000;  // 2014-06-01

    /// Defaults for a board running `f`: modern is the default configuration; rover2 speaks MAVLink 1,
    /// reports reached waypoints by text only, re-requests a missing mission item after 500 ms and stops
    /// listening 1 s after the last one (GCS_Mavlink.pde of APMrover2 2.43).
    static RoverSimConfig for_firmware(Firmware f);
    static std::vector<std::string> validate(const RoverSimConfig& c);
};

/// Faults that can be switched while running.
struct Faults {
    /// Fraction of the bytes lost, in each direction. With loss_burst <= 1 each byte is lost on its own;
    /// above, bytes go in bursts of that mean length (geometric), so a burst cuts a frame short, takes the
    /// tail of one frame and the head of the next, or swallows whole frames, as a radio fade does.
    double loss = 0;
    double loss_burst = 1;  // mean length of a loss burst, bytes
    double corrupt = 0;     // probability each byte (either direction) has one bit flipped
    bool ignore_mission = false;
    Duration slow{0};  // delay of every answer to a request
};

enum class BootPhase : std::uint8_t { Silent, Calibrating, Ready };
std::string_view phase_name(BootPhase p);

struct ModeChange {
    TimePoint at{};
    RoverMode from = RoverMode::Initialising;
    RoverMode to = RoverMode::Initialising;
    std::string cause;  // "mission end", "command", "rc pilot", "reboot", "rtl end", "power on"
    std::uint16_t current_seq = 0;
    std::size_t mission_count = 0;  // items stored, home included
};

struct ReachedEvent {
    TimePoint at{};
    std::uint16_t seq = 0;
    double distance = 0;  // metres from the item when it counted as reached
    bool passed = false;  // went past it rather than inside WP_RADIUS
    GeoPoint item;        // where the reached item was
    // The leg that ended here, timed in AUTO only (from the item before being reached, the mission started
    // or a HOLD ended): its seconds and the median of the car's speed over them, m/s (0 for no time).
    double leg_s = 0;
    double median_speed = 0;
    std::uint16_t command = 0;  // its MAV_CMD (NAV_WAYPOINT, or NAV_LOITER_UNLIM where the rover stays)
};

/// A change of the speed the rover drives at in AUTO, RTL and GUIDED (modern: WP_SPEED as AUTO was entered,
/// or a DO_CHANGE_SPEED; rover2: CRUISE_SPEED).
struct SpeedChange {
    TimePoint at{};
    double speed = 0;       // m/s
    std::string cause;      // "power on", "reboot", "param" (PARAM_SET), "control", "command line",
                            // "command" (COMMAND_LONG), "mission", "mode" (AUTO, GUIDED or RTL entered)
    std::uint16_t seq = 0;  // current mission item then (for "mission": the DO_CHANGE_SPEED item)
};

struct SimState {
    BootPhase phase = BootPhase::Silent;
    RoverMode mode = RoverMode::Initialising;
    bool armed = false;
    GeoPoint position;
    double heading_deg = 0;
    double speed = 0;
    std::uint16_t current_seq = 0;
    std::size_t mission_count = 0;
    std::optional<GeoPoint> target;
    double target_distance = 0;
    std::uint32_t time_boot_ms = 0;
    std::uint32_t boots = 0;
    double battery_remaining = 100;  // percent
    double odometer = 0;             // metres
    double cruise_speed = 0;         // m/s the rover drives at when navigating
    bool gps_fix = true;             // the GPS has a fix (control: gps)
    std::string failing_check;       // an arming check made to fail (control: fail-check), "" if none
};

struct SimCounters {
    std::uint64_t bytes_in = 0;
    std::uint64_t bytes_out = 0;
    std::uint64_t bytes_lost = 0;       // by the loss fault, both directions
    std::uint64_t bytes_corrupted = 0;  // by the corruption fault, both directions
    std::uint64_t frames_in = 0;
    std::uint64_t frames_ignored = 0;  // not for us, while silent, or mission frames while ignoring
    std::uint64_t bad_checksum =
        0;  // frames whose checksum failed (rover2: also ids it has no CRC_EXTRA for)
    std::uint64_t mavlink2_ignored = 0;  // MAVLink 2 frames a MAVLink 1 only board met (its 0xFD start bytes)
    std::uint64_t heartbeats_sent = 0;
    std::uint64_t heartbeats_stalled = 0;
    std::uint64_t auto_restarts = 0;  // "Auto mission changed, restarted command" (the change detector)
    std::uint64_t arm_refused = 0;    // arming attempts that failed their checks
    Duration heartbeat_gap_max{0};    // the longest time between two heartbeats sent, in board time
};

/// A silence of the board: its heartbeats stopped for longer than RoverSim::kLongHeartbeatGap (a stall
/// fault, a reboot, or the simulator itself not running). Ended at `at`.
struct HeartbeatGap {
    TimePoint at;
    Duration length;
};

class RoverSim {
  public:
    static constexpr std::uint8_t kSysid = 1;
    static constexpr std::uint8_t kCompid = 1;
    static constexpr std::size_t kMaxReachedLog = 4096;
    static constexpr std::size_t kMaxSpeedLog = 4096;
    static constexpr std::size_t kMaxLegSamples = std::size_t{1} << 20;  // speed samples kept for one leg
    /// A heartbeat gap this long (the board beats at 1 Hz) is a silence, kept in long_heartbeat_gaps().
    static constexpr Duration kLongHeartbeatGap = seconds(5);
    static constexpr std::size_t kMaxHeartbeatGaps = 64;  // the latest kept

    RoverSim(RoverSimConfig config, TimePoint now);

    void handle_bytes(std::span<const std::uint8_t> bytes, TimePoint now);
    void handle_timeout(TimePoint now);
    std::vector<std::uint8_t> poll_transmit();
    TimePoint poll_timeout() const;

    /// A program opened the port (the board sees DTR): reboots when reset_on_open.
    void port_opened(TimePoint now);
    void reboot(TimePoint now);
    /// Reboots when simulated time reaches `at` (kNever cancels).
    void schedule_reboot(TimePoint at) { reboot_at_ = at; }
    /// The RC pilot flips the mode switch. False while the board is not ready.
    bool rc_pilot(RoverMode mode, TimePoint now);
    /// The board changes mode by itself (as its failsafe would): recorded with cause "board". False while
    /// the board is not ready, or when the firmware refuses (no such mode, AUTO without a mission).
    bool force_mode(RoverMode mode, TimePoint now);
    /// Sets (and saves) a parameter from outside MAVLink: the control socket, the command line. A speed
    /// change is logged with `cause`.
    bool set_param(const std::string& name, float value, TimePoint now, const std::string& cause = "control");
    /// Arms (as MAV_CMD_COMPONENT_ARM_DISARM would; `force`: the checks skipped, as param2 21196 does) or
    /// disarms. Returns the MAV_RESULT the command gets.
    std::uint8_t arm(bool on, bool force, TimePoint now);
    /// The GPS gets (true) or loses its fix: without one the board has no position estimate, which an
    /// arming check in the modes that need a position refuses ("Need Position Estimate").
    void set_gps_fix(bool fix, TimePoint now);
    /// An arming check that fails with `reason` (as "PreArm: <reason>" and "Arm: <reason>") until cleared
    /// with "".
    void fail_check(std::string reason, TimePoint now);
    /// Heartbeats stop for `d` from `now` (everything else goes on).
    void stall_heartbeats(Duration d, TimePoint now) { hb_stall_until_ = now + d; }
    /// Stops (true) or restarts the vehicle's motion (its physics clock): while frozen it keeps its place,
    /// heading and speed, so it reaches nothing, while the clock, heartbeats, telemetry, modes and the
    /// mission protocol go on. A test holds the vehicle still with it while a ground program, however slow
    /// on a loaded machine, acts, instead of racing the accelerated clock.
    void freeze(bool on, TimePoint now);
    bool frozen() const { return frozen_; }
    /// A fresh battery, as swapped in the field between runs: nothing consumed from `now` on.
    void swap_battery(TimePoint now);

    Faults& faults() { return faults_; }
    const Faults& faults() const { return faults_; }
    SimState state() const;
    const std::vector<ModeChange>& mode_history() const { return mode_history_; }
    const std::deque<ReachedEvent>& reached() const { return reached_; }
    /// Reached events ever logged; reached().front() is number reached_total() - reached().size().
    std::uint64_t reached_total() const { return reached_total_; }
    /// Changes of the navigation speed, the oldest first (the last kMaxSpeedLog); the first is the power-on
    /// value. speed_log().front() is number speed_log_total() - speed_log().size().
    const std::deque<SpeedChange>& speed_log() const { return speed_log_; }
    std::uint64_t speed_log_total() const { return speed_log_total_; }
    /// The speed the rover drives at when navigating, m/s.
    double cruise_speed() const;
    const ParamTable& params() const { return params_; }
    ParamTable& params() { return params_; }
    const MissionStore& mission() const { return store_; }
    const FtpServerStats& ftp_stats() const { return ftp_.stats(); }
    const MissionServerStats& mission_stats() const {
        return rover2_mission() ? legacy_server_.stats() : server_.stats();
    }
    const SimCounters& counters() const { return counters_; }
    /// The board's silences, the latest kMaxHeartbeatGaps, oldest first.
    const std::deque<HeartbeatGap>& long_heartbeat_gaps() const { return long_heartbeat_gaps_; }
    const RoverSimConfig& config() const { return config_; }
    TimePoint started() const { return started_; }

  private:
    // rover_sim.cpp: time, boot, bytes, faults
    void advance(TimePoint now);
    void enter_phase(BootPhase phase, TimePoint now);
    void dispatch(const mavlink::Frame& f, TimePoint now);
    void impair(std::vector<std::uint8_t>& bytes, bool& in_burst);
    bool lose_byte(bool& in_burst);
    double uniform();
    void text(std::uint8_t severity, std::string_view message);
    void new_parser();
    bool addressed(std::uint8_t target_system) const {
        return target_system == kSysid || (target_system == 0 && config_.firmware.broadcast_target);
    }
    bool rover2_mission() const { return config_.firmware.mission == Dialect::Rover2; }
    bool rover2_commands() const { return config_.firmware.commands == Dialect::Rover2; }
    bool rover2_telemetry() const { return config_.firmware.telemetry == Dialect::Rover2; }
    // banner.cpp: the firmware's banner texts
    void send_banner();
    // Speed: the log and what changes the speed.
    void note_speed(const std::string& cause, TimePoint now, std::optional<std::uint16_t> seq = {});
    void set_unsaved_param(const std::string& name, float value);
    std::uint32_t time_boot_ms(TimePoint now) const;
    std::uint64_t unix_us(TimePoint now) const;
    // rover_sim_nav.cpp: modes, navigation, physics
    bool set_mode(RoverMode mode, const std::string& cause, TimePoint now);
    void physics_step(TimePoint at);
    void load_item(std::uint16_t seq, TimePoint now);
    void on_target_reached(double distance, bool passed, TimePoint now);
    bool set_current(std::uint16_t seq, TimePoint now);
    bool guided_goto(const StoredItem& item);
    void mission_changed();
    bool physics_active() const;
    DriveLimits limits() const;
    GeoPoint home_point() const { return config_.home; }
    // rover_sim_commands.cpp: parameters, commands, RC
    void on_param(const mavlink::Frame& f);
    void send_param(std::size_t index, std::optional<std::uint16_t> reported_index = std::nullopt);
    void apply_param_side_effects(const std::string& name, const std::string& cause, TimePoint now);
    void on_command_long(const mavlink::Frame& f, TimePoint now);
    void on_command(const mavlink::CommandLong& c, const mavlink::Frame& f, TimePoint now);
    // rover_sim_gcs_services.cpp: COMMAND_INT, TIMESYNC and MAVLink FTP (modern firmware)
    void on_command_int(const mavlink::Frame& f, TimePoint now);
    std::uint8_t do_reposition(const mavlink::CommandInt& c, TimePoint now);
    void on_timesync(const mavlink::Frame& f, TimePoint now);
    void on_set_position_target(const mavlink::Frame& f);
    void on_ftp(const mavlink::Frame& f);
    void on_set_mode(const mavlink::Frame& f, TimePoint now);
    void on_request_data_stream(const mavlink::Frame& f, TimePoint now);
    void on_rc_override(const mavlink::Frame& f, TimePoint now);
    void load_stream_rates(TimePoint now);
    // rover_sim_arming.cpp: the arming checks and their reports
    bool is_armed() const;
    std::uint8_t arm_disarm(bool on, bool force);
    std::vector<std::string> failing_checks() const;
    void arming_update(TimePoint now);
    // rover_sim_nav.cpp: the modern navigation (S-curve speeds, the change detector, timed waypoints)
    void nav_modern_step(double dt, const DriveLimits& lim, TimePoint at);
    double corner_speed_here(double cruise, const DriveLimits& lim, bool& stop) const;
    void check_mission_change(TimePoint now);
    void continue_after(std::uint16_t seq, TimePoint now);
    void note_leg_speed(double speed);
    void take_leg_stats(ReachedEvent& event);
    // rover_sim_telemetry.cpp
    void send_heartbeat(TimePoint now);
    void note_heartbeat_sent(TimePoint now);
    void send_stream_message(std::uint32_t msgid, TimePoint now);
    void send_mission_current();
    void send_home_position();
    void send_autopilot_version();
    std::uint16_t rc_input(int channel, TimePoint now) const;
    // rover_sim_rover2.cpp: the APMrover2 2.4x command processor, modes and command handlers
    bool r2_set_mode(RoverMode mode, const std::string& cause, TimePoint now);
    void r2_boot_ready(TimePoint now);
    void r2_restart_nav(TimePoint now);
    void r2_process_next_command(TimePoint now);
    void r2_process_nav_cmd(TimePoint now);
    void r2_process_non_nav_command(TimePoint now);
    void r2_do_jump(TimePoint now);
    void r2_do_change_speed(TimePoint now);
    void r2_do_rtl(const std::string& cause, TimePoint now);
    void r2_set_next_wp(const GeoPoint& wp);
    void r2_change_command(std::uint16_t seq, TimePoint now);
    void r2_guided_goto(const StoredItem& item, TimePoint now);
    void r2_tick(TimePoint now);
    bool r2_verify_nav(TimePoint now);
    bool r2_verify_condition(TimePoint now);
    bool r2_verify_rtl();
    void r2_reached(bool passed, double distance, TimePoint now);
    StoredItem r2_cmd(int index) const;
    std::int32_t home_alt_cm() const;
    void r2_text(std::uint8_t severity, std::string_view message);
    void r2_on_command_long(const mavlink::Frame& f, TimePoint now);
    void r2_on_set_mode(const mavlink::Frame& f, TimePoint now);
    void r2_send_heartbeat();

    RoverSimConfig config_;
    TimePoint started_;
    TimePoint now_;
    std::mt19937_64 rng_;
    bool burst_in_ = false;   // loss burst under way, bytes to the board
    bool burst_out_ = false;  // loss burst under way, bytes from the board
    Faults faults_;
    SimCounters counters_;
    ParamTable params_;
    FtpServer ftp_{params_};
    MissionStore store_;
    Outbox out_;
    MissionServer server_;
    LegacyMissionServer legacy_server_;
    StreamScheduler streams_;
    std::unique_ptr<mavlink::Parser> parser_;      // modern: MAVLink 1 and 2
    std::unique_ptr<LegacyParser> legacy_parser_;  // rover2: the MAVLink 1.0 receiver
    bool parsing_ = false;
    bool reboot_during_parse_ = false;
    VehicleModel vehicle_;

    BootPhase phase_ = BootPhase::Silent;
    TimePoint phase_until_ = kNever;
    TimePoint boot_started_{};
    std::uint32_t boots_ = 0;
    TimePoint reboot_at_ = kNever;
    TimePoint next_heartbeat_ = kNever;
    TimePoint last_heartbeat_sent_ = kNever;
    std::deque<HeartbeatGap> long_heartbeat_gaps_;
    TimePoint hb_stall_until_{};
    TimePoint last_step_{};
    bool frozen_ = false;

    RoverMode mode_ = RoverMode::Initialising;
    bool armed_ = false;
    // Arming (modern): what fails, and AP_Arming::update()'s reporting state.
    bool gps_fix_ = true;
    std::string failing_check_;
    bool prearm_failing_ = false;
    bool report_immediately_ = false;
    TimePoint last_prearm_display_{};
    std::vector<ModeChange> mode_history_;

    // Navigation: the target is a copy of the item's location, taken when the item became current.
    std::uint16_t current_seq_ = 0;
    bool mission_running_ = false;
    bool mission_complete_ = false;
    std::optional<GeoPoint> target_;
    std::optional<GeoPoint> leg_start_;
    std::optional<GeoPoint> guided_target_;
    std::deque<ReachedEvent> reached_;
    std::uint64_t reached_total_ = 0;       // ever logged, including those dropped from reached_
    std::vector<std::int32_t> jumps_done_;  // per item: DO_JUMP repeats taken (reset by a new mission)
    bool loitering_ = false;                // arrived at a NAV_LOITER_UNLIM item: stay there
    // Modern navigation: the S-curve's planned speed (restarts from 0 when the leg is re-planned from where
    // the car is), a waypoint's hold time being held, the change detector, the leg's speed samples.
    double planned_speed_ = 0;
    std::optional<TimePoint> wait_until_;
    MissionChangeDetector change_detector_;
    std::vector<float> leg_speeds_;  // the car's speed at each physics step of the leg, in AUTO

    std::array<std::uint16_t, 8> rc_override_{};  // 0: not overridden
    TimePoint rc_override_at_{};
    double consumed_mah_ = 0;

    // Speed. Modern: AR_WPNav's speed, WP_SPEED as it was when AUTO, GUIDED or RTL was last entered, or what
    // a DO_CHANGE_SPEED set since (speed_override_; WP_SPEED itself before any of them). Rover2:
    // CRUISE_SPEED; DO_CHANGE_SPEED writes it in RAM only, so a reboot brings the saved value back
    // (unsaved_params_).
    std::optional<double> speed_override_;
    std::map<std::string, float> unsaved_params_;  // name -> value saved in EEPROM
    std::deque<SpeedChange> speed_log_;
    std::uint64_t speed_log_total_ = 0;

    // The APMrover2 2.4x command processor (commands_process.pde), its variables as the firmware has them.
    struct Rover2Nav {
        std::uint8_t nav_index = 0;      // nav_command_index
        std::uint8_t non_nav_index = 0;  // non_nav_command_index
        std::uint8_t nav_id = 0;         // nav_command_ID (0: NO_COMMAND)
        std::uint8_t non_nav_id = 0;     // non_nav_command_ID (0: NO_COMMAND, 255: WAIT_COMMAND)
        std::int32_t command_index = 0;  // g.command_index: MISSION_CURRENT
        StoredItem next_nav;
        StoredItem next_nonnav;
        GeoPoint next_wp;  // next_WP
        GeoPoint prev_wp;  // prev_WP
        TimePoint condition_start{};
        std::int32_t condition_value = 0;
        std::int32_t condition_rate = 0;
        TimePoint next_tick = kNever;  // the 10 Hz navigate() / update_commands() tasks
    };
    Rover2Nav r2_;
};

}  // namespace airseg::apmsim
