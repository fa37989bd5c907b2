#pragma once
// Lazy expansion of a Plan into a stream of waypoints. Memory is O(nesting depth + one scan line), never
// O(plan): a scan of a million waypoints is produced one line at a time.
//
// Cost of seek(n) (used to resume after a restart): O(elements walked) + O(1) per scan line before the
// target inside the scan it lands in (+ O(vertices) per line). A repeat whose body holds no goto is skipped
// in O(body) whatever its count; gotos are followed one by one. For a 1,000,000-waypoint scan of 500,000
// lines the seek touches each line once (no per-waypoint work).
//
// Second line of defence against no-fly zones: every leg between two consecutive positioned waypoints is
// checked while streaming (when `enforce_no_fly`); a violating leg stops the stream before the offending
// waypoint and error() says why. The first leg after a seek or a jump is not checked (its start is wherever
// the vehicle is).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "services/flightplan/plan.hpp"
#include "services/flightplan/waypoint.hpp"

namespace airseg::flightplan {

class Expander final : public WaypointStream {
  public:
    /// fold_repeats (for validation only): a goto-free repeat runs two iterations, then the stream moves past
    /// it (indices still count all iterations); a goto-free repeat forever ends the stream after two.
    explicit Expander(std::shared_ptr<const Plan> plan, bool enforce_no_fly = true,
                      bool fold_repeats = false);

    std::optional<Waypoint> next() override;
    /// Seeks relative to the current origin (the plan start unless a jump happened); an index before the
    /// origin cannot be reached (returns false).
    bool seek(std::uint64_t index) override;
    bool jump_to(std::string_view element_name) override;
    std::string element_path(std::uint32_t element) const override;
    std::optional<std::string> error() const override { return error_; }

    /// Continue at element `node`, counting indices on from the current position.
    bool jump_to_node(std::uint32_t node);
    /// Rebuild a stream saved as (origin, index of the next waypoint).
    bool restore(StreamOrigin origin, std::uint64_t index);

    std::uint64_t position() const { return position_; }
    StreamOrigin origin() const { return origin_; }
    const Plan& plan() const { return *plan_; }

  private:
    struct Frame {
        std::uint32_t node;
        std::uint32_t next_child;
        std::uint64_t iteration;
        const NodeExtra* box = nullptr;  // the container's children and repeat count, looked up once
    };

    bool seek_from_here(std::uint64_t index);
    void reset_to_origin();
    void place_at(std::uint32_t node);
    /// Walks the element tree until a leaf with waypoints is active. False at the end of the plan.
    bool activate_next_leaf(std::uint64_t* skip_budget);
    void activate_leaf(std::uint32_t node, std::uint64_t offset);
    Waypoint make_waypoint();
    const std::optional<std::uint64_t>& body_count(std::uint32_t repeat) const;

    std::shared_ptr<const Plan> plan_;
    bool enforce_no_fly_;
    bool fold_repeats_;
    std::vector<std::pair<std::uint32_t, std::optional<std::uint64_t>>>
        body_count_;               // per repeat, by id: waypoints of one iteration
    std::vector<Box> zone_boxes_;  // per no-fly zone, buffer included
    std::vector<Frame> stack_;
    StreamOrigin origin_;
    std::uint64_t position_ = 0;

    std::uint32_t leaf_ = kNoNode;
    const NodeExtra* leaf_extra_ = nullptr;  // looked up once per leaf, not per waypoint
    std::uint64_t leaf_offset_ = 0;
    std::uint64_t leaf_count_ = 0;
    std::uint64_t scan_line_ = 0;
    std::uint64_t scan_line_start_ = 0;  // leaf offset of the current line's first waypoint
    ScanPattern::Line line_;

    double speed_ = 0.0;
    bool speed_changed_ = false;
    std::optional<Enu> last_position_;
    std::optional<std::string> error_;
};

}  // namespace airseg::flightplan
