// The plan and track exports: GeoJSON structure (RFC 7946) and KML text.
#include <gtest/gtest.h>

#include "ground/map/plan_export.hpp"

namespace airseg::ground {
namespace {

using Json = nlohmann::json;

const Json kGeometry = Json::parse(R"({
  "name": "a <b> & \"c\"",
  "elements": [
    {"path": "plan.elements[0]", "kind": "waypoint", "name": "start", "closed": false, "points": [[41.0, 2.0]]},
    {"path": "plan.elements[1]", "kind": "scan", "name": null, "closed": true,
     "points": [[41.0, 2.0], [41.1, 2.0], [41.1, 2.1]], "lines": [[41.01, 2.01], [41.09, 2.01]]},
    {"path": "plan.elements[2]", "kind": "hold", "name": "", "closed": false, "hold_s": null, "points": []},
    {"path": "plan.elements[3]", "kind": "orbit", "name": "o", "closed": false,
     "points": [[41.2, 2.2], [41.3, 2.3]]}
  ],
  "no_fly": [{"name": "pond & <lake>", "points": [[40.0, 1.0], [40.0, 1.1], [39.9, 1.1]]}]
})");

TEST(MapExport, PlanGeoJsonIsAFeatureCollectionInLonLatOrder) {
    const auto g = plan_geojson(kGeometry);
    EXPECT_EQ(g["type"], "FeatureCollection");
    const auto& f = g["features"];
    ASSERT_EQ(f.size(), 5u) << g.dump(1);  // point, area, lines, orbit line, zone; the empty hold is left out
    for (const auto& feature : f) {
        EXPECT_EQ(feature["type"], "Feature");
        EXPECT_TRUE(feature["properties"].is_object());
    }
    EXPECT_EQ(f[0]["geometry"], Json::parse(R"({"type":"Point","coordinates":[2.0,41.0]})"));
    EXPECT_EQ(f[1]["geometry"]["type"], "Polygon");
    const auto& ring = f[1]["geometry"]["coordinates"][0];
    ASSERT_EQ(ring.size(), 4u);
    EXPECT_EQ(ring.front(), ring.back()) << "a linear ring is closed";
    EXPECT_EQ(f[2]["geometry"]["type"], "LineString");
    EXPECT_EQ(f[2]["properties"]["kind"], "scan-lines");
    EXPECT_EQ(f[3]["geometry"]["coordinates"][1], Json::parse("[2.3, 41.3]"));
    EXPECT_EQ(f[4]["properties"]["kind"], "no_fly");
    EXPECT_EQ(f[4]["geometry"]["type"], "Polygon");
}

TEST(MapExport, AMalformedGeometryGivesAnEmptyCollection) {
    EXPECT_TRUE(plan_geojson(Json()).at("features").empty());
    EXPECT_TRUE(
        plan_geojson(Json::parse(R"({"elements":[{"points":[["x",1],[1]]}]})")).at("features").empty());
}

TEST(MapExport, TrackGeoJsonHasTheTrackAndItsTimes) {
    EXPECT_TRUE(track_geojson({}).at("features").empty());
    std::deque<TrackPoint> track;
    const auto t0 = std::chrono::system_clock::time_point(std::chrono::milliseconds(1714564800250));
    track.push_back({41.0, 2.0, 10.0, 90.0, 1.0, t0});
    EXPECT_EQ(track_geojson(track)["features"][0]["geometry"]["type"], "Point");
    track.push_back({41.1, 2.1, 11.0, 90.0, 1.0, t0 + std::chrono::seconds(1)});
    const auto g = track_geojson(track);
    EXPECT_EQ(g["features"][0]["geometry"]["type"], "LineString");
    EXPECT_EQ(g["features"][0]["geometry"]["coordinates"][1], Json::parse("[2.1, 41.1, 11.0]"));
    EXPECT_EQ(g["features"][0]["properties"]["times"][0], "2024-05-01T12:00:00.250Z");
}

TEST(MapExport, KmlEscapesNamesAndWritesLonLat) {
    EXPECT_EQ(xml_escape("a<b>&\"c'\x01"), "a&lt;b&gt;&amp;&quot;c&apos; ");
    const auto kml = plan_kml(kGeometry);
    EXPECT_TRUE(kml.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>"));
    EXPECT_NE(kml.find("<name>a &lt;b&gt; &amp; &quot;c&quot;</name>"), std::string::npos);
    EXPECT_NE(kml.find("<name>pond &amp; &lt;lake&gt;</name>"), std::string::npos);
    EXPECT_EQ(kml.find("<lake>"), std::string::npos);
    EXPECT_NE(kml.find("<Point><coordinates>2,41,0</coordinates></Point>"), std::string::npos);
    EXPECT_NE(kml.find("<Polygon>"), std::string::npos);
    EXPECT_TRUE(kml.ends_with("</Document>\n</kml>\n"));

    std::deque<TrackPoint> track{{41.0, 2.0, 10.0, 0, 0, {}}, {41.5, 2.5, 12.5, 0, 0, {}}};
    EXPECT_NE(track_kml(track).find("<coordinates>2,41,10 2.5,41.5,12.5</coordinates>"), std::string::npos);
}

}  // namespace
}  // namespace airseg::ground
