#pragma once
// The WindowFeeder's vocabulary, in autopilot-neutral terms: the autopilot driver translates these into
// its own protocol (for ArduPilot: MISSION_COUNT/ITEM_INT uploads, MISSION_WRITE_PARTIAL_LIST,
// MISSION_SET_CURRENT, DO_JUMP, NAV_LOITER_UNLIM, mode changes).
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <variant>
#include <vector>

#include "services/flightplan/geo.hpp"
#include "services/flightplan/waypoint.hpp"

namespace airseg::flightplan {

/// One slot of the autopilot's mission.
struct MissionItem {
    enum class Kind : std::uint8_t {
        Waypoint,  // drive to position; the autopilot reports it reached and moves to the next slot
        Stop,      // stay at position; the mission does not advance past it (ArduPilot: NAV_LOITER_UNLIM)
        JumpTo,    // continue at jump_slot, forever (ArduPilot: DO_JUMP with repeat -1)
    };
    Kind kind = Kind::Waypoint;
    LatLon position;
    std::optional<double> alt;
    double speed = 0.0;           // m/s on the leg to this item
    double arrival_radius = 0.0;  // metres
    std::uint16_t jump_slot = 0;
    bool operator==(const MissionItem&) const = default;
};

/// Replace the whole mission with `items` at slots 1..n (slot 0, home, is the driver's business).
struct UploadMission {
    std::vector<MissionItem> items;
};
/// Overwrite existing slots first_slot..first_slot+n-1 (a partial write; the mission keeps its length).
struct WriteItems {
    std::uint16_t first_slot = 1;
    std::vector<MissionItem> items;
};
/// Make `slot` the autopilot's current target.
struct SetCurrent {
    std::uint16_t slot = 1;
};
/// Stop automatic navigation where the vehicle is (ArduPilot Rover: HOLD mode).
struct HoldVehicle {};
/// Follow the mission from the current target (ArduPilot: AUTO mode).
struct ResumeMission {};

struct FeederRequest {
    std::uint32_t id = 0;
    std::variant<UploadMission, WriteItems, SetCurrent, HoldVehicle, ResumeMission> op;
};
std::ostream& operator<<(std::ostream& os, const FeederRequest& request);

enum class RequestResult : std::uint8_t {
    Ok,
    Failed,   // not confirmed (timeout, link down, busy): asked again
    Refused,  // the autopilot said no to the content (a mission it does not take): asking again cannot help
};

/// The autopilot's navigation mode, as far as the feeder cares.
enum class VehicleMode : std::uint8_t {
    Unknown,  // link down, booting
    Auto,     // following its mission (ArduPilot: AUTO)
    Hold,     // stopped (HOLD)
    Manual,   // someone drives by hand (the RC pilot, the ground joystick)
};
/// Who changed the mode.
enum class ModeCause : std::uint8_t {
    Ours,     // this daemon asked for it (the feeder, or an operator's state command)
    Board,    // the autopilot itself (end of its mission, a failsafe, a mode switch it treats as its own)
    RcPilot,  // the RC pilot took the vehicle (MANUAL)
};

enum class PlanState : std::uint8_t {
    None,
    Running,
    Paused,
    Done,
    Interrupted,  // the vehicle left AUTO by itself or was taken by hand; why: FeederProgress::interruption
    Failed,       // the autopilot refused the plan's mission items; why: FeederProgress::failure
};
const char* to_string(PlanState state);

struct FeederEvent {
    enum class Kind : std::uint8_t {
        ElementStarted,   // the vehicle heads to the element's first waypoint
        ElementFinished,  // the element's last waypoint was reached
        WaypointReached,  // plan_index reached (each index reported once)
        HoldStarted,
        HoldEnded,
        PlanDone,
        PlanBlocked,    // the stream stopped on an error (detail); the vehicle stops after the last good one
        RequestFailed,  // a request exhausted its retry budget (detail); the vehicle is held
        WindowStarved,  // the next target was not on the autopilot in time; the vehicle is held
        Interrupted,    // the vehicle left AUTO without the feeder asking (detail: why and what follows)
        Continued,      // back in AUTO after an interruption
        PlanFailed,     // the autopilot refused the plan's items (detail: its answer); the vehicle is held
    };
    Kind kind = Kind::WaypointReached;
    std::uint32_t generation = 0;  // which plan (replace_plan increments it)
    std::uint64_t plan_index = 0;
    std::uint32_t element = 0;
    std::string element_path;
    std::string detail;
};
const char* to_string(FeederEvent::Kind kind);

/// What the daemon exposes as plan.* status fields.
struct FeederProgress {
    PlanState state = PlanState::None;           // plan.state
    std::string plan_name;                       // plan.name
    std::string element;                         // plan.element (path of the element being flown)
    std::uint64_t waypoints_reached = 0;         // plan.waypoints_reached
    std::optional<std::uint64_t> next_waypoint;  // plan.next_waypoint (plan index of the current target)
    std::size_t window = 0;                      // plan.window (plan waypoints on the autopilot, confirmed)
    std::uint32_t generation = 0;
    // Where to resume after a restart: the first unreached waypoint (or the hold being held).
    StreamOrigin resume_origin;
    std::optional<std::uint64_t> resume_index;
    // Health counters.
    std::string interruption{};  // the last interruption (kept after the plan continued), "" if none
    std::string failure{};       // why the plan failed, "" unless state is Failed
    std::uint64_t interruptions = 0;
    std::uint64_t starvation_holds = 0;
    std::uint64_t retargets = 0;  // the vehicle reached its target while the next slot's write was in flight
    std::uint64_t ignored_reached = 0;  // duplicate or late reached reports
    std::uint64_t retries = 0;
    std::uint64_t failures = 0;
};

}  // namespace airseg::flightplan
