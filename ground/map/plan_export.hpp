#pragma once
// The plan (the answer of plan.geometry) and the vehicle's track as GeoJSON (RFC 7946: [lon, lat] order,
// closed polygon rings) and KML 2.2, for other map programs. Pure functions of their input.
#include <chrono>
#include <deque>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace airseg::ground {

struct TrackPoint {
    double lat = 0.0;
    double lon = 0.0;
    double alt = 0.0;
    double heading = 0.0;  // degrees clockwise from north
    double speed = 0.0;    // m/s over ground
    std::chrono::system_clock::time_point at;
};

/// Text made safe for XML character data and attribute values.
std::string xml_escape(std::string_view text);

/// A FeatureCollection: each element a LineString (or a Point when it has one point, a Polygon when
/// closed), a scan's lines a LineString of their own, each no-fly zone a Polygon; properties carry the
/// element's path, kind, name and hold time.
nlohmann::json plan_geojson(const nlohmann::json& geometry);
/// A FeatureCollection with one LineString of the track (empty collection without points) and its times.
nlohmann::json track_geojson(const std::deque<TrackPoint>& track);

std::string plan_kml(const nlohmann::json& geometry);
std::string track_kml(const std::deque<TrackPoint>& track);

/// RFC 3339 UTC time with milliseconds ("2024-05-01T12:00:00.250Z").
std::string utc_time(std::chrono::system_clock::time_point at);

}  // namespace airseg::ground
