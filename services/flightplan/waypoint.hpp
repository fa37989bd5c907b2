#pragma once
// One element of the expanded plan, and the interface every waypoint source (the expander, a test list)
// offers to the rolling-window feeder.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "services/flightplan/geo.hpp"

namespace airseg::flightplan {

enum class WaypointAction : std::uint8_t {
    Go,                 // drive to the position and carry on
    HoldFor,            // drive to the position (if any), then hold for hold_seconds
    HoldUntilReleased,  // drive to the position (if any), then hold until the operator releases
};
const char* to_string(WaypointAction action);

/// Where an expansion started: the plan's beginning (element == kStreamStart) or the element a jump (goto
/// reaction, operator command) landed on, at stream index `index`. Together with a stream index it is
/// enough to rebuild the stream after a restart.
struct StreamOrigin {
    static constexpr std::uint32_t kStreamStart = 0xFFFFFFFFu;
    std::uint32_t element = kStreamStart;
    std::uint64_t index = 0;
    bool operator==(const StreamOrigin&) const = default;
};

struct Waypoint {
    std::uint64_t index = 0;    // position in the expanded stream, 0-based, stable
    std::uint32_t element = 0;  // id of the plan element it came from (see element_path())
    WaypointAction action = WaypointAction::Go;
    bool has_position = true;  // false only for a hold at "wherever the previous waypoint ends"
    LatLon position;
    Enu local;
    std::optional<double> alt;      // metres, relative to home
    double speed = 0.0;             // m/s on the leg to this waypoint
    bool speed_changed = false;     // a speed element took effect just before this waypoint
    double arrival_radius = 0.0;    // metres
    double hold_seconds = 0.0;      // HoldFor
    bool first_of_element = false;  // the element starts with this waypoint
    bool last_of_element = false;   // the element ends with this waypoint
    StreamOrigin origin;
};

class WaypointStream {
  public:
    virtual ~WaypointStream() = default;
    /// The next waypoint, or nothing at the end of the plan (or when the stream stopped on an error).
    virtual std::optional<Waypoint> next() = 0;
    /// Restart the stream so that next() returns the waypoint with this index. False if it does not exist,
    /// and then the stream is where it was (a skip past the end must not lose what comes next).
    virtual bool seek(std::uint64_t index) = 0;
    /// Continue the stream at the named element; indices keep counting. False if no such element.
    virtual bool jump_to(std::string_view element_name) = 0;
    virtual std::string element_path(std::uint32_t element) const = 0;
    /// Why the stream ended early (e.g. a leg entering a no-fly zone), if it did.
    virtual std::optional<std::string> error() const = 0;
};

}  // namespace airseg::flightplan
