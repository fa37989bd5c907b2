#pragma once
// Plane geometry for plans of rover scale: an equirectangular local frame (east/north metres around a
// reference point, radii of curvature of the WGS84 ellipsoid at the reference latitude) and the few
// polygon/segment predicates the validator, the expander and the reaction monitor need.
//
// Error bound of the local frame: the east scale is exact on the reference parallel and drifts by
// tan(lat0) * dn / R (relative) at a north offset dn; the north scale drifts by about 1.5 e^2 sin(2 lat0)
// dn / R. Within 5 km of the reference and below 60 degrees of latitude the position error stays under
// 5 km * 1.73 * 5 km / 6.37e6 m ~= 7 m, and under 0.3 m within 1 km: ample for rover-scale plans,
// not for cross-country plane legs.
#include <span>
#include <vector>

namespace airseg::flightplan {

inline constexpr double kWgs84SemiMajorAxis = 6378137.0;  // metres
inline constexpr double kWgs84Flattening = 1.0 / 298.257223563;
inline constexpr double kWgs84EccentricitySq = kWgs84Flattening * (2.0 - kWgs84Flattening);
inline constexpr double kPi = 3.14159265358979323846;

struct LatLon {
    double lat = 0.0;  // degrees, north positive
    double lon = 0.0;  // degrees, east positive
    bool operator==(const LatLon&) const = default;
};

struct Enu {
    double e = 0.0;  // metres east of the reference
    double n = 0.0;  // metres north of the reference
    bool operator==(const Enu&) const = default;
};

/// How far a plan's positions may lie from its frame's reference, and how near the poles: beyond, the local
/// frame stops being a map at all (longitudes wrap at ±180°, a degree of longitude shrinks to nothing at a
/// pole), and a polygon around the globe shrank in it to a sliver of a few metres. Within the reach the
/// frame is still off by up to tan(lat₀)·Δn²/R (the bound above): about 1.4 km at 41° and 100 km, 35 m at
/// 16 km; a plan that spans more than a few kilometres should set its reference near its middle.
inline constexpr double kMaxFrameReachMetres = 100'000.0;
inline constexpr double kMaxFrameLatitude = 85.0;

/// Great-circle distance on a sphere of the Earth's mean radius: the measure of kMaxFrameReachMetres,
/// independent of the local frame it bounds.
double great_circle_distance(LatLon a, LatLon b);

/// Equirectangular projection around a reference point (see the error bound above).
class LocalFrame {
  public:
    LocalFrame() : LocalFrame(LatLon{}) {}
    explicit LocalFrame(LatLon reference);

    Enu to_local(LatLon p) const;
    LatLon to_geo(Enu p) const;
    LatLon reference() const { return ref_; }

  private:
    LatLon ref_;
    double metres_per_rad_lat_;
    double metres_per_rad_lon_;
};

/// Axis-aligned bounds, used to skip the exact zone tests for legs far from a zone.
struct Box {
    double min_e = 0.0, min_n = 0.0, max_e = 0.0, max_n = 0.0;
    static Box around(std::span<const Enu> points, double margin);
    /// True when the bounding box of segment a-b overlaps this box.
    bool may_touch(Enu a, Enu b) const;
};

double distance(Enu a, Enu b);
double distance_point_segment(Enu p, Enu a, Enu b);
double distance_segment_segment(Enu a, Enu b, Enu c, Enu d);
bool segments_intersect(Enu a, Enu b, Enu c, Enu d);
/// Even-odd rule; a point on the boundary may count either way (callers add a buffer).
bool point_in_polygon(Enu p, std::span<const Enu> polygon);
/// Distance from p to the polygon's boundary.
double distance_to_boundary(Enu p, std::span<const Enu> polygon);
/// True when the segment a-b enters the polygon or passes closer than `buffer` metres to it.
bool segment_violates_zone(Enu a, Enu b, std::span<const Enu> polygon, double buffer);
/// True when the polygon's edges cross each other (not a simple polygon).
bool polygon_self_intersects(std::span<const Enu> polygon);

}  // namespace airseg::flightplan
