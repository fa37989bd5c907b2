#pragma once
// The autopilot-neutral interface: what flightplan, groundlink and status see of the autopilot. Plain
// structs, no MAVLink; they travel on the bus. A driver (ardupilot/) translates them to and from its
// autopilot's protocol, so nothing outside services/autopilot/ depends on one vendor's structures.
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "services/common/reply.hpp"

namespace airseg::autopilot {

/// The vehicle states of the USAL virtual autopilot, as the rest of the system reasons about them.
enum class VehicleState : std::uint8_t {
    Unknown,             // no heartbeat yet, or link down
    ConfigureCheck,      // booting, calibrating, being configured
    Parking,             // stopped (Rover HOLD)
    Directed,            // RC pilot driving (Rover MANUAL)
    ManualNavigation,    // ground joystick driving through RC override (Rover MANUAL + override)
    WaypointNavigation,  // following the mission fed by the flight plan manager (Rover AUTO)
    Manual,              // failsafe: RC pilot only; leaving it needs an explicit operator reset
};
const char* to_string(VehicleState s);
std::optional<VehicleState> vehicle_state_from_string(std::string_view text);
std::ostream& operator<<(std::ostream& os, VehicleState s);

enum class GpsFix : std::uint8_t { None, NoFix, Fix2D, Fix3D, Dgps, RtkFloat, RtkFixed };

struct Position {
    double lat = 0.0;  // degrees
    double lon = 0.0;  // degrees
    double alt = 0.0;  // metres above mean sea level
    bool operator==(const Position&) const = default;
};

struct Telemetry {
    std::optional<Position> position;  // empty until the autopilot reports a valid one
    // Why `position` is empty although the autopilot reported one: no GPS fix, 0/0 before a fix, or a value
    // that is no place (latitude 199.17); empty while the position is valid or none was reported.
    std::string position_invalid;
    double relative_alt = 0.0;                  // metres above home
    double roll = 0.0, pitch = 0.0, yaw = 0.0;  // radians
    double ground_speed = 0.0;                  // m/s
    double heading = 0.0;                       // degrees, 0..360
    GpsFix gps_fix = GpsFix::None;
    unsigned satellites = 0;
    std::optional<double> battery_voltage;  // volts
    std::optional<int> battery_remaining;   // percent
    std::optional<double> battery_current;  // amperes
    std::string mode;                       // the autopilot's own mode name ("AUTO", "HOLD", ...)
    // The same mode as the autopilot's own number (ArduPilot: the heartbeat's custom_mode), for whoever
    // forwards it without knowing the autopilot's names (the ground protocol). Empty exactly when `mode` is.
    std::optional<std::uint32_t> custom_mode;
    VehicleState state = VehicleState::Unknown;
    std::uint16_t mission_current = 0;
    std::optional<Position> home;
    bool operator==(const Telemetry&) const = default;
};

/// One slot of the autopilot's mission, in neutral terms.
struct MissionItem {
    enum class Kind : std::uint8_t {
        Waypoint,  // drive to position, then continue with the next slot
        Stop,      // stay at position indefinitely (ArduPilot: NAV_LOITER_UNLIM)
        JumpTo,    // continue at jump_slot, forever (ArduPilot: DO_JUMP, repeat -1)
    };
    Kind kind = Kind::Waypoint;
    double lat = 0.0;
    double lon = 0.0;
    double alt = 0.0;              // metres, relative to home
    std::optional<double> speed;   // m/s on the leg to this item (informational for Rover)
    std::optional<double> radius;  // acceptance radius, metres
    std::optional<double> hold_s;  // seconds to wait on arrival
    std::uint16_t jump_slot = 0;
    bool operator==(const MissionItem&) const = default;
};

// --- events (every one delivered) --------------------------------------------------------------------------
struct WaypointReached {
    std::uint16_t seq = 0;
};
/// A mission item of a running partial write is on the board (the board asked for the next one), told in
/// order with the board's reports, before the write's result: a report of that slot read after it is of
/// this item.
struct MissionItemStored {
    std::uint16_t slot = 0;
    MissionItem item;
};
enum class ModeChangeCause : std::uint8_t {
    Requested,  // the change this system asked for
    External,   // the RC pilot, the autopilot itself (failsafe, end of mission), another ground station
};
struct ModeChanged {
    VehicleState from = VehicleState::Unknown;
    VehicleState to = VehicleState::Unknown;
    std::string from_mode, to_mode;  // the autopilot's own names
    ModeChangeCause cause = ModeChangeCause::External;
};
struct LinkUp {};
struct LinkDown {
    std::string reason;
};
/// The autopilot restarted on its own: its parameters and mission were resynchronised; whoever keeps state on
/// it (the flight plan manager's window) must rebuild it.
struct AutopilotRebooted {
    std::string evidence;  // "time_boot_ms went back from 81234 to 2100 ms and ran on from there"
};
struct Ready {
    double seconds_from_open = 0.0;
};
struct StatusText {
    int severity = 6;
    std::string text;
};
/// The autopilot moved on to another mission slot (on its own, or after a set-current request).
struct MissionCurrentChanged {
    std::uint16_t seq = 0;
};

// --- requests and their results
// ------------------------------------------------------------------------------
enum class RequestResult : std::uint8_t {
    Ok,
    Refused,    // the autopilot answered no, or the transition is not allowed from the current state
    Timeout,    // no confirmation within the retry budget
    Busy,       // another operation of the same kind is running
    NotReady,   // the autopilot is not connected / not READY
    Invalid,    // bad arguments (named in detail)
    Cancelled,  // the link went down or the autopilot rebooted while the request ran
};
const char* to_string(RequestResult r);
std::ostream& operator<<(std::ostream& os, RequestResult r);

enum class RequestKind : std::uint8_t {
    SetState,
    UploadMission,
    WriteItems,
    DownloadMission,
    SetCurrent,
    ClearMission,
    GetParam,
    SetParam,
    ListParams,
};
const char* to_string(RequestKind k);

struct RequestDone {
    std::uint32_t id = 0;
    RequestKind kind = RequestKind::SetState;
    RequestResult result = RequestResult::Ok;
    std::string detail;                                  // for people, when not ok
    std::vector<MissionItem> items;                      // DownloadMission
    std::optional<double> param_value;                   // GetParam / SetParam (the value read back)
    std::vector<std::pair<std::string, double>> params;  // ListParams: the cached table, by name
    std::optional<bool> armed;  // SetState: the board's heartbeat showed it armed at the end (when known)
    /// UploadMission, WriteItems: the board runs a Stop as the end of its mission and holds there in HOLD (an
    /// APM:Rover 2.x has no NAV_LOITER_UNLIM: its Stops are jumps past the end); false: it stays in AUTO.
    std::optional<bool> stop_ends_mission;
};

using Event = std::variant<WaypointReached, MissionCurrentChanged, ModeChanged, LinkUp, LinkDown,
                           AutopilotRebooted, Ready, StatusText, RequestDone, MissionItemStored>;

// --- bus requests to the autopilot service (answered through their Reply)
// -----------------------------------
struct RequestStateChange {
    VehicleState state = VehicleState::Parking;
};
struct UploadMission {
    std::vector<MissionItem> items;  // slots 1..n; slot 0 (home) is the driver's
};
struct WriteMissionItems {
    std::uint16_t first_slot = 1;
    std::vector<MissionItem> items;
};
struct DownloadMission {};
struct SetMissionCurrent {
    std::uint16_t slot = 1;
};
struct ClearMission {};
struct GetParam {
    std::string name;
};
struct SetParam {
    std::string name;
    double value = 0.0;
};
/// The parameter table as downloaded at connection (and kept current by every set and PARAM_VALUE).
struct ListParams {};
struct AutopilotRequest {
    std::variant<RequestStateChange, UploadMission, WriteMissionItems, DownloadMission, SetMissionCurrent,
                 ClearMission, GetParam, SetParam, ListParams>
        op;
    // Answered once, when the request is finished; its fallback should be not_answered(), which is what the
    // requester gets when no service takes the request. RequestDone::id is then the driver's own number.
    Reply<RequestDone> reply;
};
/// The fallback of an AutopilotRequest's Reply: no autopilot service took the request.
RequestDone not_answered();
/// Ground joystick input, -1..1 each; it drives only in MANUAL_NAVIGATION and only while it keeps coming.
struct JoystickInput {
    double steering = 0.0;
    double throttle = 0.0;
};
/// The operator's explicit reset out of failsafe MANUAL.
struct OperatorReset {};

/// One frame from the autopilot for standard ground stations (QGroundControl, Mission Planner), published as
/// an event for each frame while forwarding is on. The bytes are opaque outside this room; the autopilot
/// room says how it must travel: the freshest value of a telemetry message is all a ground station needs,
/// while an answer it waits for (a parameter value, an acknowledgement, a mission item, a text) must arrive.
struct ForwardedFrame {
    enum class Delivery : std::uint8_t { Freshest, Reliable };
    std::uint32_t id = 0;  // the message id, to rate-limit each kind on its own
    Delivery delivery = Delivery::Freshest;
    std::vector<std::uint8_t> bytes;  // one whole frame
};
/// Whole frames from a standard ground station for the autopilot, unchecked: the autopilot service parses
/// them, keeps mission writes from the autopilot (the flight plan manager owns the mission: an upload
/// becomes a GroundStationMission) and writes the rest to the autopilot.
struct GroundStationFrames {
    std::vector<std::uint8_t> bytes;
};

/// The flight plan manager's verdict on a ground station's mission.
struct GroundStationMissionResult {
    bool accepted = false;
    std::string reason;  // for the ground station's operator, when refused
};
/// A mission a standard ground station uploaded, received by the autopilot room in the autopilot's name
/// instead of being written to it: the flight plan manager loads it as its plan or refuses it. The ground
/// station gets MISSION_ACK once the reply came.
struct GroundStationMission {
    std::string station;             // "SYSID/COMPID", for logs
    std::vector<MissionItem> items;  // Waypoint (with hold_s for a timed hold) or Stop; home left out
    Reply<GroundStationMissionResult> reply;
};

/// What status shows as autopilot.* keys.
struct AutopilotStatus {
    bool link_up = false;                        // autopilot.link
    bool ready = false;                          // autopilot.ready
    std::optional<double> ready_s;               // autopilot.ready_s: open -> first READY, seconds
    VehicleState state = VehicleState::Unknown;  // autopilot.state
    std::string mode;                            // autopilot.mode
    std::optional<Position> position;            // autopilot.position (only a valid place)
    std::string position_invalid;                // autopilot.position_invalid: why there is none; "" if none
    std::uint16_t mission_current = 0;           // autopilot.mission_current
    unsigned reboots = 0;                        // autopilot.reboots
    unsigned link_losses = 0;                    // autopilot.link_losses: heartbeats overdue, link down
    unsigned link_verdicts_deferred = 0;  // autopilot.link_verdicts_deferred: overdue, the port not read out
    unsigned syncs = 0;                   // autopilot.syncs: parameter + mission downloads started
    unsigned reconnects = 0;              // autopilot.reconnects (filled by the service from its port keeper)
    unsigned reset_pulses = 0;            // autopilot.reset_pulses
    std::optional<bool> armed;            // autopilot.armed: the heartbeat's SAFETY_ARMED; empty before one
    unsigned arm_refusals = 0;            // autopilot.arm_refusals: arming attempts the board refused
    std::optional<double> speed;          // autopilot.speed: the leg speed the board last confirmed, m/s
    std::string mission_items = "int";    // autopilot.mission_items: "int" (MISSION_ITEM_INT) or "float"
    unsigned auto_restarts_corrected = 0;  // autopilot.auto_restarts_corrected: slots set back after AUTO
    unsigned baud = 0;  // autopilot.baud: the rate the port runs at (the one kept when probing)
    // autopilot.refused_values: values from the autopilot not taken (NaN, out of range), and the last one
    std::uint64_t refused_values = 0;
    std::string refused_value;
    // autopilot.params: names cached, announced by the autopilot (PARAM_COUNT), and dropped past the bound
    std::size_t params_cached = 0;
    std::size_t params_announced = 0;
    std::uint64_t params_dropped = 0;
    // autopilot.ground_stations (filled by the service): mission uploads refused for their size, and with the
    // MAVLink endpoint on, its UDP peers and TCP clients now, peers forgotten to make room, clients refused
    std::uint64_t gcs_missions_too_large = 0;
    // The autopilot's frames addressed to airsegd itself (its mission and command traffic): kept from every
    // ground station, the endpoint's and the radio's, as mavlink-router keeps them.
    std::uint64_t gcs_to_airsegd_kept = 0;
    bool gcs_endpoint = false;
    std::size_t gcs_udp_peers = 0;
    std::size_t gcs_tcp_clients = 0;
    std::uint64_t gcs_udp_peers_evicted = 0;
    std::uint64_t gcs_tcp_refused = 0;
    std::uint64_t gcs_frames_in = 0;    // valid frames from ground stations, passed on
    std::uint64_t gcs_invalid_in = 0;   // damaged or unknown frames from ground stations, dropped
    std::uint64_t gcs_dropped_out = 0;  // sends to a ground station dropped (its queue full)
    // autopilot.tlog (filled by the service from its .tlog writer; absent when recording is off)
    bool tlog_enabled = false;
    std::uint64_t tlog_write_errors = 0;    // autopilot.tlog.write_errors
    std::uint64_t tlog_dropped_frames = 0;  // autopilot.tlog.dropped_frames: lost to write errors
    std::string tlog_error;                 // autopilot.tlog.error: the last write error, "" when none yet
    bool operator==(const AutopilotStatus&) const = default;
};

}  // namespace airseg::autopilot
