// The local frame against published WGS84 degree lengths, and the segment/zone predicates.
#include <gtest/gtest.h>

#include "services/flightplan/geo.hpp"

namespace airseg::flightplan {
namespace {

TEST(FlightplanGeo, DegreeLengthsMatchWgs84Tables) {
    // One degree at 45 degrees of latitude: 111,132 m of latitude, 78,847 m of longitude (WGS84).
    const LocalFrame f({45.0, 10.0});
    EXPECT_NEAR(f.to_local({46.0, 10.0}).n, 111'132.0, 5.0);
    EXPECT_NEAR(f.to_local({45.0, 11.0}).e, 78'847.0, 5.0);
    const LocalFrame eq({0.0, 0.0});
    EXPECT_NEAR(eq.to_local({1.0, 0.0}).n, 110'574.0, 5.0);
    EXPECT_NEAR(eq.to_local({0.0, 1.0}).e, 111'320.0, 5.0);
}

TEST(FlightplanGeo, RoundTripAndDateLine) {
    const LocalFrame f({41.2752, 1.9868});
    for (LatLon p : {LatLon{41.28, 1.99}, LatLon{41.27, 1.98}, LatLon{41.2752, 1.9868}}) {
        const LatLon back = f.to_geo(f.to_local(p));
        EXPECT_NEAR(back.lat, p.lat, 1e-12);
        EXPECT_NEAR(back.lon, p.lon, 1e-12);
    }
    const LocalFrame dl({0.0, 179.9999});
    EXPECT_NEAR(dl.to_local({0.0, -179.9999}).e, 22.26, 0.01);  // across the date line, not around the globe
}

TEST(FlightplanGeo, ZonePredicatesHonourTheBuffer) {
    const std::vector<Enu> square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
    EXPECT_TRUE(point_in_polygon({5, 5}, square));
    EXPECT_FALSE(point_in_polygon({15, 5}, square));
    EXPECT_TRUE(segment_violates_zone({-5, 5}, {15, 5}, square, 0.0));     // straight through
    EXPECT_FALSE(segment_violates_zone({-5, 13}, {15, 13}, square, 2.0));  // 3 m clear of a 2 m buffer
    EXPECT_TRUE(segment_violates_zone({-5, 13}, {15, 13}, square, 4.0));   // inside a 4 m buffer
    EXPECT_TRUE(segment_violates_zone({2, 2}, {3, 3}, square, 0.0));       // wholly inside
    EXPECT_TRUE(polygon_self_intersects(std::vector<Enu>{{0, 0}, {10, 10}, {10, 0}, {0, 10}}));
    EXPECT_FALSE(polygon_self_intersects(square));
    const Box b = Box::around(square, 2.0);
    EXPECT_TRUE(b.may_touch({-5, 11}, {15, 11}));
    EXPECT_FALSE(b.may_touch({-5, 13}, {15, 13}));
}

}  // namespace
}  // namespace airseg::flightplan
