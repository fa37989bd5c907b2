#include "services/flightplan/geo.hpp"

#include <algorithm>
#include <cmath>

namespace airseg::flightplan {

namespace {
constexpr double kDegToRad = kPi / 180.0;

double cross(Enu o, Enu a, Enu b) {
    return (a.e - o.e) * (b.n - o.n) - (a.n - o.n) * (b.e - o.e);
}

bool on_segment(Enu p, Enu a, Enu b) {
    return std::min(a.e, b.e) <= p.e && p.e <= std::max(a.e, b.e) && std::min(a.n, b.n) <= p.n &&
           p.n <= std::max(a.n, b.n);
}
}  // namespace

double great_circle_distance(LatLon a, LatLon b) {
    constexpr double kMeanRadius = 6'371'008.8;  // metres (IUGG)
    const double dlat = (b.lat - a.lat) * kDegToRad;
    const double dlon = (b.lon - a.lon) * kDegToRad;
    const double h = std::sin(dlat / 2) * std::sin(dlat / 2) + std::cos(a.lat * kDegToRad) *
                                                                   std::cos(b.lat * kDegToRad) *
                                                                   std::sin(dlon / 2) * std::sin(dlon / 2);
    return 2.0 * kMeanRadius * std::asin(std::min(1.0, std::sqrt(h)));
}

LocalFrame::LocalFrame(LatLon reference) : ref_(reference) {
    const double s = std::sin(reference.lat * kDegToRad);
    const double w = 1.0 - kWgs84EccentricitySq * s * s;
    const double prime_vertical = kWgs84SemiMajorAxis / std::sqrt(w);
    const double meridional = kWgs84SemiMajorAxis * (1.0 - kWgs84EccentricitySq) / (w * std::sqrt(w));
    metres_per_rad_lat_ = meridional;
    metres_per_rad_lon_ = prime_vertical * std::cos(reference.lat * kDegToRad);
}

Enu LocalFrame::to_local(LatLon p) const {
    double dlon = p.lon - ref_.lon;
    if (dlon > 180.0) {
        dlon -= 360.0;
    }
    if (dlon < -180.0) {
        dlon += 360.0;
    }
    return {dlon * kDegToRad * metres_per_rad_lon_, (p.lat - ref_.lat) * kDegToRad * metres_per_rad_lat_};
}

LatLon LocalFrame::to_geo(Enu p) const {
    double lon = ref_.lon + p.e / metres_per_rad_lon_ / kDegToRad;
    if (lon > 180.0) {
        lon -= 360.0;
    }
    if (lon < -180.0) {
        lon += 360.0;
    }
    return {ref_.lat + p.n / metres_per_rad_lat_ / kDegToRad, lon};
}

Box Box::around(std::span<const Enu> points, double margin) {
    Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (const Enu p : points) {
        b.min_e = std::min(b.min_e, p.e - margin);
        b.min_n = std::min(b.min_n, p.n - margin);
        b.max_e = std::max(b.max_e, p.e + margin);
        b.max_n = std::max(b.max_n, p.n + margin);
    }
    return b;
}

bool Box::may_touch(Enu a, Enu b) const {
    return std::max(a.e, b.e) >= min_e && std::min(a.e, b.e) <= max_e && std::max(a.n, b.n) >= min_n &&
           std::min(a.n, b.n) <= max_n;
}

double distance(Enu a, Enu b) {
    return std::hypot(a.e - b.e, a.n - b.n);
}

double distance_point_segment(Enu p, Enu a, Enu b) {
    const double de = b.e - a.e, dn = b.n - a.n;
    const double len2 = de * de + dn * dn;
    if (len2 <= 0.0) {
        return distance(p, a);
    }
    const double t = std::clamp(((p.e - a.e) * de + (p.n - a.n) * dn) / len2, 0.0, 1.0);
    return distance(p, {a.e + t * de, a.n + t * dn});
}

bool segments_intersect(Enu a, Enu b, Enu c, Enu d) {
    const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) {
        return true;
    }
    return (d1 == 0 && on_segment(a, c, d)) || (d2 == 0 && on_segment(b, c, d)) ||
           (d3 == 0 && on_segment(c, a, b)) || (d4 == 0 && on_segment(d, a, b));
}

double distance_segment_segment(Enu a, Enu b, Enu c, Enu d) {
    if (segments_intersect(a, b, c, d)) {
        return 0.0;
    }
    return std::min({distance_point_segment(a, c, d), distance_point_segment(b, c, d),
                     distance_point_segment(c, a, b), distance_point_segment(d, a, b)});
}

bool point_in_polygon(Enu p, std::span<const Enu> polygon) {
    bool inside = false;
    const std::size_t n = polygon.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        const Enu a = polygon[i], b = polygon[j];
        if ((a.n > p.n) != (b.n > p.n)) {
            const double e_cross = a.e + (p.n - a.n) * (b.e - a.e) / (b.n - a.n);
            if (p.e < e_cross) {
                inside = !inside;
            }
        }
    }
    return inside;
}

double distance_to_boundary(Enu p, std::span<const Enu> polygon) {
    double best = INFINITY;
    const std::size_t n = polygon.size();
    for (std::size_t i = 0; i < n; ++i) {
        best = std::min(best, distance_point_segment(p, polygon[i], polygon[(i + 1) % n]));
    }
    return best;
}

bool segment_violates_zone(Enu a, Enu b, std::span<const Enu> polygon, double buffer) {
    if (polygon.size() < 3) {
        return false;
    }
    if (point_in_polygon(a, polygon) || point_in_polygon(b, polygon)) {
        return true;
    }
    const std::size_t n = polygon.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Enu c = polygon[i], d = polygon[(i + 1) % n];
        if (buffer <= 0.0 ? segments_intersect(a, b, c, d) : distance_segment_segment(a, b, c, d) < buffer) {
            return true;
        }
    }
    return false;
}

bool polygon_self_intersects(std::span<const Enu> polygon) {
    const std::size_t n = polygon.size();
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j) {
            // Adjacent edges share a vertex by construction.
            if (j == i + 1 || (i == 0 && j == n - 1)) {
                continue;
            }
            if (segments_intersect(polygon[i], polygon[(i + 1) % n], polygon[j], polygon[(j + 1) % n])) {
                return true;
            }
        }
    }
    return false;
}

}  // namespace airseg::flightplan
