#include "ground/map/plan_export.hpp"

#include <fmt/format.h>

#include <ctime>

namespace airseg::ground {

using Json = nlohmann::json;

namespace {

/// [lat, lon] pairs of the geometry answer as GeoJSON positions ([lon, lat]); malformed pairs are dropped.
Json positions(const Json& points, bool close_ring) {
    Json out = Json::array();
    if (!points.is_array()) {
        return out;
    }
    for (const auto& p : points) {
        if (p.is_array() && p.size() >= 2 && p[0].is_number() && p[1].is_number()) {
            out.push_back(Json::array({p[1], p[0]}));
        }
    }
    if (close_ring && !out.empty() && out.front() != out.back()) {
        out.push_back(out.front());
    }
    return out;
}

Json feature(Json geometry, Json properties) {
    return {{"type", "Feature"}, {"geometry", std::move(geometry)}, {"properties", std::move(properties)}};
}

/// The geometry for a list of positions: nothing for none, a Point for one, else a LineString or Polygon.
Json shape(const Json& points, bool closed) {
    Json pos = positions(points, closed);
    if (pos.empty()) {
        return nullptr;
    }
    if (pos.size() == 1) {
        return {{"type", "Point"}, {"coordinates", pos[0]}};
    }
    if (closed && pos.size() >= 4) {
        return {{"type", "Polygon"}, {"coordinates", Json::array({std::move(pos)})}};
    }
    return {{"type", "LineString"}, {"coordinates", std::move(pos)}};
}

std::string string_of(const Json& j, const char* key) {
    const auto it = j.find(key);
    return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

const Json& array_of(const Json& j, const char* key) {
    static const Json kEmpty = Json::array();
    if (!j.is_object()) {
        return kEmpty;
    }
    const auto it = j.find(key);
    return it != j.end() && it->is_array() ? *it : kEmpty;
}

std::string kml_coordinates(const Json& points, bool close_ring) {
    std::string out;
    for (const auto& p : positions(points, close_ring)) {
        out += fmt::format("{},{},0 ", p[0].get<double>(), p[1].get<double>());
    }
    if (!out.empty()) {
        out.pop_back();
    }
    return out;
}

std::string kml_placemark(const std::string& name, const std::string& style, const std::string& description,
                          const Json& points, bool closed) {
    const std::string coords = kml_coordinates(points, closed);
    if (coords.empty()) {
        return {};
    }
    std::string geometry;
    const auto count = positions(points, false).size();
    if (count == 1) {
        geometry = "<Point><coordinates>" + coords + "</coordinates></Point>";
    } else if (closed && count >= 3) {
        geometry = "<Polygon><outerBoundaryIs><LinearRing><coordinates>" + coords +
                   "</coordinates></LinearRing></outerBoundaryIs></Polygon>";
    } else {
        geometry =
            "<LineString><tessellate>1</tessellate><coordinates>" + coords + "</coordinates></LineString>";
    }
    return "<Placemark><name>" + xml_escape(name) + "</name><description>" + xml_escape(description) +
           "</description><styleUrl>#" + style + "</styleUrl>" + geometry + "</Placemark>\n";
}

constexpr std::string_view kKmlHead =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml "
    "xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n";
constexpr std::string_view kKmlStyles =
    "<Style id=\"plan\"><LineStyle><color>ffff7f00</color><width>3</width></LineStyle>"
    "<PolyStyle><color>40ff7f00</color></PolyStyle></Style>\n"
    "<Style id=\"no_fly\"><LineStyle><color>ff0000ff</color><width>2</width></LineStyle>"
    "<PolyStyle><color>600000ff</color></PolyStyle></Style>\n"
    "<Style id=\"track\"><LineStyle><color>ff00a5ff</color><width>3</width></LineStyle></Style>\n";

}  // namespace

std::string xml_escape(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&apos;";
                break;
            default:
                // XML 1.0 forbids most control characters even when escaped.
                if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r') {
                    out += ' ';
                } else {
                    out += c;
                }
        }
    }
    return out;
}

std::string utc_time(std::chrono::system_clock::time_point at) {
    using namespace std::chrono;
    const auto ms = duration_cast<milliseconds>(at.time_since_epoch()).count();
    const std::time_t secs = static_cast<std::time_t>(ms >= 0 ? ms / 1000 : (ms - 999) / 1000);
    std::tm tm{};
    gmtime_r(&secs, &tm);
    return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}Z", tm.tm_year + 1900, tm.tm_mon + 1,
                       tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, ((ms % 1000) + 1000) % 1000);
}

Json plan_geojson(const Json& geometry) {
    Json features = Json::array();
    for (const auto& e : array_of(geometry, "elements")) {
        if (!e.is_object()) {
            continue;
        }
        const bool closed = e.value("closed", false);
        Json props = {
            {"path", string_of(e, "path")}, {"kind", string_of(e, "kind")}, {"name", string_of(e, "name")}};
        if (e.contains("hold_s")) {
            props["hold_s"] = e["hold_s"];
        }
        if (auto g = shape(array_of(e, "points"), closed); !g.is_null()) {
            features.push_back(feature(std::move(g), props));
        }
        if (auto g = shape(array_of(e, "lines"), false); !g.is_null()) {
            props["kind"] = string_of(e, "kind") + "-lines";
            features.push_back(feature(std::move(g), props));
        }
    }
    for (const auto& z : array_of(geometry, "no_fly")) {
        if (auto g = shape(array_of(z, "points"), true); !g.is_null()) {
            features.push_back(feature(std::move(g), {{"kind", "no_fly"}, {"name", string_of(z, "name")}}));
        }
    }
    Json out = {{"type", "FeatureCollection"}, {"features", std::move(features)}};
    if (geometry.is_object() && geometry.contains("name") && geometry["name"].is_string()) {
        out["name"] = geometry["name"];
    }
    return out;
}

Json track_geojson(const std::deque<TrackPoint>& track) {
    Json features = Json::array();
    if (!track.empty()) {
        Json coords = Json::array();
        Json times = Json::array();
        for (const auto& p : track) {
            coords.push_back(Json::array({p.lon, p.lat, p.alt}));
            times.push_back(utc_time(p.at));
        }
        // A lone point is still a track: a Point, as a LineString needs two positions.
        Json g = coords.size() == 1 ? Json{{"type", "Point"}, {"coordinates", coords[0]}}
                                    : Json{{"type", "LineString"}, {"coordinates", std::move(coords)}};
        features.push_back(feature(std::move(g), {{"kind", "track"}, {"times", std::move(times)}}));
    }
    return {{"type", "FeatureCollection"}, {"features", std::move(features)}};
}

std::string plan_kml(const Json& geometry) {
    std::string out(kKmlHead);
    const std::string name = geometry.is_object() ? string_of(geometry, "name") : std::string();
    out += "<name>" + xml_escape(name.empty() ? "airseg plan" : name) + "</name>\n";
    out += kKmlStyles;
    for (const auto& e : array_of(geometry, "elements")) {
        if (!e.is_object()) {
            continue;
        }
        const std::string title = string_of(e, "name").empty() ? string_of(e, "path") : string_of(e, "name");
        const std::string what = string_of(e, "kind") + " " + string_of(e, "path");
        out += kml_placemark(title, "plan", what, array_of(e, "points"), e.value("closed", false));
        out += kml_placemark(title + " (lines)", "plan", what, array_of(e, "lines"), false);
    }
    for (const auto& z : array_of(geometry, "no_fly")) {
        out += kml_placemark(string_of(z, "name"), "no_fly", "no-fly zone", array_of(z, "points"), true);
    }
    out += "</Document>\n</kml>\n";
    return out;
}

std::string track_kml(const std::deque<TrackPoint>& track) {
    std::string out(kKmlHead);
    out += "<name>airseg track</name>\n";
    out += kKmlStyles;
    if (!track.empty()) {
        // gx:Track would carry the times too, but plain LineString is what every KML reader draws.
        std::string coords;
        for (const auto& p : track) {
            coords += fmt::format("{},{},{} ", p.lon, p.lat, p.alt);
        }
        coords.pop_back();
        out += "<Placemark><name>track</name><description>" + xml_escape(utc_time(track.front().at)) +
               " to " + xml_escape(utc_time(track.back().at)) + "</description><styleUrl>#track</styleUrl>";
        out += track.size() == 1 ? "<Point><coordinates>" + coords + "</coordinates></Point>"
                                 : "<LineString><tessellate>1</tessellate><coordinates>" + coords +
                                       "</coordinates></LineString>";
        out += "</Placemark>\n";
    }
    out += "</Document>\n</kml>\n";
    return out;
}

}  // namespace airseg::ground
