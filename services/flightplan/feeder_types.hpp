#pragma once
// The WindowFeeder's own vocabulary: its requests, events and progress. What it asks of the autopilot is
// the autopilot's neutral vocabulary (services/autopilot/autopilot.hpp), which the driver translates into its
// own protocol (for ArduPilot: MISSION_COUNT/ITEM_INT uploads, MISSION_WRITE_PARTIAL_LIST,
// MISSION_SET_CURRENT, DO_JUMP, NAV_LOITER_UNLIM, mode changes).
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <variant>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/autopilot.hpp"
#include "services/flightplan/waypoint.hpp"

namespace airseg::flightplan {

/// A request to the autopilot, in the autopilot's own neutral terms: a whole-mission upload (slots 1..n;
/// slot 0, home, is the driver's), a partial write (the mission keeps its length), a new current target, or
/// a state change (Parking to stop where the vehicle is, WaypointNavigation to follow the mission).
struct FeederRequest {
    std::uint32_t id = 0;  // the feeder's own number, matched by on_request_result()
    std::variant<autopilot::UploadMission, autopilot::WriteMissionItems, autopilot::SetMissionCurrent,
                 autopilot::RequestStateChange>
        op;
};
std::ostream& operator<<(std::ostream& os, const FeederRequest& request);

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
        PlanBlocked,     // the stream stopped on an error (detail); the vehicle stops after the last good one
        RequestFailed,   // a request exhausted its retry budget (detail); the vehicle is held
        WindowStarved,   // the autopilot headed for a slot whose content was not confirmed; it is held
        HeldAtFrontier,  // the vehicle stopped at the window's barrier: the next waypoint was not written in
                         // time (once per stop); it goes on once the write lands
        Interrupted,     // the vehicle left AUTO without the feeder asking (detail: why and what follows)
        Continued,       // back in AUTO after an interruption
        PlanFailed,      // the autopilot refused the plan's items (detail: its answer); the vehicle is held
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
    std::uint32_t extensions = 0;  // plans appended to this one since it was loaded
    // Where to resume after a restart: the first unreached waypoint (or the hold being held).
    StreamOrigin resume_origin;
    std::optional<std::uint64_t> resume_index;
    // Health counters.
    std::string interruption{};  // the last interruption (kept after the plan continued), "" if none
    std::string failure{};       // why the plan failed, "" unless state is Failed
    std::uint64_t interruptions = 0;
    std::uint64_t starvation_holds = 0;
    bool held_at_frontier = false;      // plan.held_at_frontier: waiting at the barrier for a write now
    std::string held;                   // plan.held: path of the element being held now, "" if none
    bool held_until_released = false;   // plan.held_until_released: that hold waits for plan resume
    std::uint64_t frontier_stops = 0;   // plan.frontier_stops: times the vehicle waited at the barrier
    Duration frontier_wait{};           // plan.frontier_wait_s: time spent waiting there (ended waits)
    std::uint64_t ignored_reached = 0;  // duplicate or late reached reports
    std::uint64_t retries = 0;
    std::uint64_t failures = 0;
};

}  // namespace airseg::flightplan
