#pragma once
// Boustrophedon coverage of a polygon, computed one sweep line at a time so that a scan of a million
// waypoints never exists in memory as a whole.
//
// Lines run along `heading` (degrees clockwise from north) and are `spacing` metres apart; line k lies at
// cross-track offset vmin + (k + 1/2) spacing (clamped inside the polygon), so every point of the polygon
// is within spacing/2 of a line. Even lines run with the heading, odd lines against it. On a line the
// waypoints span the first to the last crossing of the polygon (a concave notch is crossed, not skipped),
// with intermediate points every `step` metres when step > 0, and a single midpoint when the span is
// shorter than the vehicle's minimum waypoint spacing.
#include <cstdint>
#include <span>
#include <vector>

#include "services/flightplan/geo.hpp"

namespace airseg::flightplan {

class ScanPattern {
  public:
    struct Line {
        double u0 = 0.0;  // along-track start (smaller)
        double u1 = 0.0;  // along-track end
        double v = 0.0;   // cross-track offset
        std::uint64_t count = 0;
    };

    /// Beyond this many lines the pattern is refused (too_many_lines()) rather than computed.
    static constexpr std::uint64_t kMaxLines = 10'000'000;

    /// `max_work`: the most line-edge crossings (lines x vertices) counting the waypoints may take; a pattern
    /// that needs more is refused (too_many_lines()) rather than computed.
    ScanPattern(std::vector<Enu> polygon, double spacing, double heading_deg, double step, double min_spacing,
                std::uint64_t max_work = UINT64_MAX);

    bool too_many_lines() const { return too_many_lines_; }
    /// Line-edge crossings the construction took (or would have taken, when refused): lines x vertices.
    double work() const { return work_; }
    std::uint64_t line_count() const { return lines_; }
    /// Waypoints of the whole scan (computed once at construction, O(lines x vertices)).
    std::uint64_t total_count() const { return total_; }
    /// O(vertices).
    Line line(std::uint64_t k) const;
    /// Waypoint j of line k (boustrophedon direction applied).
    Enu point(std::uint64_t k, const Line& line, std::uint64_t j) const;
    const std::vector<Enu>& polygon() const { return polygon_; }
    double spacing() const { return spacing_; }

  private:
    std::vector<Enu> polygon_;
    std::vector<Enu> rotated_;  // (u, v) stored as (e, n)
    double spacing_;
    double step_;
    double min_spacing_;
    Enu along_;
    Enu across_;
    double vmin_ = 0.0;
    double vmax_ = 0.0;
    std::uint64_t lines_ = 0;
    std::uint64_t total_ = 0;
    double work_ = 0.0;
    bool too_many_lines_ = false;
};

}  // namespace airseg::flightplan
