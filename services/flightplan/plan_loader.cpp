#include "services/flightplan/plan_loader.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <map>
#include <set>
#include <sstream>

#include "services/common/nearest_word.hpp"
#include "services/flightplan/plan_validator.hpp"

namespace airseg::flightplan {

namespace {

struct RawScan {
    std::vector<LatLon> polygon;
    double spacing = 0.0;
    double heading = 0.0;
    double step = 0.0;
};

struct RawOrbit {
    double radius = 0.0;
    double turns = 1.0;
    bool clockwise = true;
};

SourceMark mark_of(const YAML::Node& node) {
    if (!node.IsDefined())
        return {};
    const YAML::Mark m = node.Mark();
    if (m.line < 0)
        return {};
    return {m.line + 1, m.column + 1};
}

class Loader {
  public:
    Loader(std::string file, std::size_t max_elements, VehicleProfile vehicle)
        : file_(std::move(file)), max_elements_(max_elements) {
        plan_.source_file = file_;
        plan_.vehicle = std::move(vehicle);
    }

    LoadResult run(const YAML::Node& doc, const LoadOptions& options);

  private:
    void error(SourceMark at, const std::string& path, std::string message) {
        errors_.push_back({file_, at.line, at.col, path, std::move(message)});
    }
    void error(const YAML::Node& at, const std::string& path, std::string message) {
        error(mark_of(at), path, std::move(message));
    }

    bool is_map(const YAML::Node& node, const std::string& path);
    void check_keys(const YAML::Node& map, const std::string& path,
                    std::initializer_list<std::string_view> allowed);
    std::optional<double> number(const YAML::Node& map, const char* key, const std::string& path,
                                 bool required, double lo, double hi, bool lo_open = false);
    std::optional<double> number_value(const YAML::Node& value, const std::string& where, double lo,
                                       double hi, bool lo_open);
    std::optional<std::string> text(const YAML::Node& map, const char* key, const std::string& path,
                                    bool required);
    std::optional<LatLon> lat_lon_fields(const YAML::Node& map, const std::string& path, bool required);
    std::optional<LatLon> point(const YAML::Node& node, const std::string& path);
    std::optional<std::vector<LatLon>> polygon(const YAML::Node& node, const std::string& path);
    void note_coordinate(LatLon p) {
        if (!first_coordinate_)
            first_coordinate_ = p;
    }

    std::uint32_t add_node(NodeKind kind, std::uint32_t parent, std::string path, SourceMark mark);
    void parse_plan(const YAML::Node& plan);
    void parse_vehicle(const YAML::Node& vehicle, const std::string& path);
    void parse_reactions(const YAML::Node& reactions, const std::string& path);
    std::optional<Reaction> parse_reaction(const YAML::Node& node, const std::string& path);
    void parse_elements(const YAML::Node& list, std::uint32_t parent, const std::string& path);
    void parse_element(const YAML::Node& item, std::uint32_t parent, const std::string& path);
    void parse_leaf_common(const YAML::Node& body, Node& node, const std::string& path);
    void parse_blocks(const YAML::Node& list, const std::string& path);

    void finish_geometry();
    void resolve_names();
    void derive_counts(const LoadOptions& options);

    std::string file_;
    std::size_t max_elements_;
    bool too_many_elements_ = false;
    Plan plan_;
    std::vector<Diagnostic> errors_;
    std::optional<LatLon> first_coordinate_;
    std::optional<LatLon> reference_;
    std::map<std::uint32_t, RawScan> scans_;
    std::map<std::uint32_t, RawOrbit> orbits_;
    std::vector<std::pair<const char*, Reaction*>> reaction_refs_;
    std::vector<std::pair<std::string, SourceMark>> reaction_paths_;
};

bool Loader::is_map(const YAML::Node& node, const std::string& path) {
    if (node.IsMap())
        return true;
    error(node, path, "must be a mapping");
    return false;
}

void Loader::check_keys(const YAML::Node& map, const std::string& path,
                        std::initializer_list<std::string_view> allowed) {
    for (auto it = map.begin(); it != map.end(); ++it) {
        const std::string key = it->first.Scalar();
        bool known = false;
        for (auto a : allowed)
            known = known || key == a;
        if (!known) {
            std::string list;
            for (auto a : allowed)
                list += (list.empty() ? "" : ", ") + std::string(a);
            error(it->first, path + "." + key,
                  "unknown field" + did_you_mean(key, allowed) + " (expected one of: " + list + ")");
        }
    }
}

std::optional<double> Loader::number(const YAML::Node& map, const char* key, const std::string& path,
                                     bool required, double lo, double hi, bool lo_open) {
    const YAML::Node value = map[key];
    const std::string where = path + "." + key;
    if (!value.IsDefined() || value.IsNull()) {
        if (required)
            error(map, where, "missing required field");
        return std::nullopt;
    }
    return number_value(value, where, lo, hi, lo_open);
}

std::optional<double> Loader::number_value(const YAML::Node& value, const std::string& where, double lo,
                                           double hi, bool lo_open) {
    double v = 0.0;
    if (!value.IsScalar() || !YAML::convert<double>::decode(value, v) || !std::isfinite(v)) {
        error(value, where, "must be a number");
        return std::nullopt;
    }
    if (!lo_open && (v < lo || v > hi)) {
        std::ostringstream msg;
        msg << "must be between " << lo << " and " << hi << " (got " << value.Scalar() << ")";
        error(value, where, msg.str());
        return std::nullopt;
    }
    if (lo_open && !(v > lo)) {
        std::ostringstream msg;
        msg << "must be > " << lo << " (got " << value.Scalar() << ")";
        error(value, where, msg.str());
        return std::nullopt;
    }
    if (!(v <= hi)) {
        std::ostringstream msg;
        msg << "must be <= " << hi << " (got " << value.Scalar() << ")";
        error(value, where, msg.str());
        return std::nullopt;
    }
    return v;
}

std::optional<std::string> Loader::text(const YAML::Node& map, const char* key, const std::string& path,
                                        bool required) {
    const YAML::Node value = map[key];
    if (!value.IsDefined() || value.IsNull()) {
        if (required)
            error(map, path + "." + key, "missing required field");
        return std::nullopt;
    }
    if (!value.IsScalar() || value.Scalar().empty()) {
        error(value, path + "." + key, "must be a non-empty string");
        return std::nullopt;
    }
    return value.Scalar();
}

std::optional<LatLon> Loader::lat_lon_fields(const YAML::Node& map, const std::string& path, bool required) {
    const bool has_lat = map["lat"].IsDefined(), has_lon = map["lon"].IsDefined();
    if (!required && !has_lat && !has_lon)
        return std::nullopt;
    const auto lat = number(map, "lat", path, true, -90.0, 90.0);
    const auto lon = number(map, "lon", path, true, -180.0, 180.0);
    if (!lat || !lon)
        return std::nullopt;
    note_coordinate({*lat, *lon});
    return LatLon{*lat, *lon};
}

std::optional<LatLon> Loader::point(const YAML::Node& node, const std::string& path) {
    if (!node.IsSequence() || node.size() != 2) {
        error(node, path, "must be a [lat, lon] pair");
        return std::nullopt;
    }
    double lat = 0.0, lon = 0.0;
    if (!YAML::convert<double>::decode(node[0], lat) || !std::isfinite(lat) || lat < -90.0 || lat > 90.0) {
        error(node[0], path + "[0]", "latitude must be a number between -90 and 90");
        return std::nullopt;
    }
    if (!YAML::convert<double>::decode(node[1], lon) || !std::isfinite(lon) || lon < -180.0 || lon > 180.0) {
        error(node[1], path + "[1]", "longitude must be a number between -180 and 180");
        return std::nullopt;
    }
    note_coordinate({lat, lon});
    return LatLon{lat, lon};
}

std::optional<std::vector<LatLon>> Loader::polygon(const YAML::Node& node, const std::string& path) {
    if (!node.IsSequence() || node.size() < 3) {
        error(node, path, "must be a list of at least 3 [lat, lon] vertices");
        return std::nullopt;
    }
    std::vector<LatLon> out;
    bool ok = true;
    for (std::size_t i = 0; i < node.size(); ++i) {
        const auto p = point(node[i], path + "[" + std::to_string(i) + "]");
        ok = ok && p.has_value();
        if (p)
            out.push_back(*p);
    }
    if (!ok)
        return std::nullopt;
    return out;
}

std::uint32_t Loader::add_node(NodeKind kind, std::uint32_t parent, std::string path, SourceMark mark) {
    const auto id = static_cast<std::uint32_t>(plan_.nodes.size());
    Node node;
    node.kind = kind;
    node.parent = parent;
    node.path = std::move(path);
    node.mark = mark;
    if (parent != kNoNode) {
        node.index_in_parent = static_cast<std::uint32_t>(plan_.nodes[parent].children.size());
        plan_.nodes[parent].children.push_back(id);
    }
    plan_.nodes.push_back(std::move(node));
    return id;
}

void Loader::parse_leaf_common(const YAML::Node& body, Node& node, const std::string& path) {
    if (auto name = text(body, "name", path, false))
        node.name = *name;
    node.alt = number(body, "alt", path, false, -1000.0, 100000.0);
    node.speed = number(body, "speed", path, false, 0.0, 1000.0, true);
}

void Loader::parse_element(const YAML::Node& item, std::uint32_t parent, const std::string& path) {
    // YAML aliases can make a small file describe an exponential number of elements.
    if (plan_.nodes.size() >= max_elements_) {
        if (!too_many_elements_)
            error(item, path, "more than " + std::to_string(max_elements_) + " elements");
        too_many_elements_ = true;
        return;
    }
    if (!item.IsMap() || item.size() != 1) {
        error(item, path,
              "an element is a mapping with exactly one of: waypoint, hold, scan, orbit, speed, repeat, "
              "block, goto");
        return;
    }
    const std::string kind = item.begin()->first.Scalar();
    const YAML::Node body = item.begin()->second;
    const std::string where = path + "." + kind;
    const SourceMark mark = mark_of(item);

    if (kind == "waypoint") {
        if (!is_map(body, where))
            return;
        check_keys(body, where, {"name", "lat", "lon", "alt", "speed", "radius"});
        const auto id = add_node(NodeKind::Waypoint, parent, path, mark);
        Node& n = plan_.nodes[id];
        parse_leaf_common(body, n, where);
        n.arrival_radius = number(body, "radius", where, false, 0.0, 100000.0, true);
        if (auto p = lat_lon_fields(body, where, true)) {
            plan_.nodes[id].geo = *p;
            plan_.nodes[id].has_position = true;
        }
    } else if (kind == "hold") {
        if (!is_map(body, where))
            return;
        check_keys(body, where, {"name", "lat", "lon", "alt", "radius", "seconds", "until_released"});
        const auto id = add_node(NodeKind::Hold, parent, path, mark);
        parse_leaf_common(body, plan_.nodes[id], where);
        plan_.nodes[id].arrival_radius = number(body, "radius", where, false, 0.0, 100000.0, true);
        if (auto p = lat_lon_fields(body, where, false)) {
            plan_.nodes[id].geo = *p;
            plan_.nodes[id].has_position = true;
        }
        plan_.nodes[id].hold_seconds = number(body, "seconds", where, false, 0.0, 7.0 * 86400.0, true);
        bool until_released = false;
        if (const YAML::Node u = body["until_released"]; u.IsDefined()) {
            if (!YAML::convert<bool>::decode(u, until_released))
                error(u, where + ".until_released", "must be true or false");
        }
        if (body["seconds"].IsDefined() == until_released) {
            error(body, where, "needs exactly one of: seconds, until_released: true");
        }
    } else if (kind == "scan") {
        if (!is_map(body, where))
            return;
        check_keys(body, where,
                   {"name", "polygon", "rectangle", "spacing", "heading", "step", "alt", "speed"});
        const auto id = add_node(NodeKind::Scan, parent, path, mark);
        parse_leaf_common(body, plan_.nodes[id], where);
        RawScan raw;
        const YAML::Node poly = body["polygon"], rect = body["rectangle"];
        if (poly.IsDefined() == rect.IsDefined()) {
            error(body, where, "needs exactly one of: polygon, rectangle");
        } else if (poly.IsDefined()) {
            if (auto p = polygon(poly, where + ".polygon"))
                raw.polygon = *p;
        } else if (is_map(rect, where + ".rectangle")) {
            check_keys(rect, where + ".rectangle", {"sw", "ne"});
            const YAML::Node sw_node = rect["sw"], ne_node = rect["ne"];
            if (!sw_node.IsDefined() || !ne_node.IsDefined()) {
                error(rect, where + ".rectangle", "needs sw: [lat, lon] and ne: [lat, lon]");
            } else {
                const auto sw = point(sw_node, where + ".rectangle.sw");
                const auto ne = point(ne_node, where + ".rectangle.ne");
                if (sw && ne) {
                    if (!(ne->lat > sw->lat) || !(ne->lon > sw->lon)) {
                        error(rect, where + ".rectangle", "ne must lie north and east of sw");
                    } else {
                        raw.polygon = {
                            {sw->lat, sw->lon}, {ne->lat, sw->lon}, {ne->lat, ne->lon}, {sw->lat, ne->lon}};
                    }
                }
            }
        }
        const auto spacing = number(body, "spacing", where, true, 0.0, 1e6, true);
        if (spacing && *spacing < plan_.vehicle.min_spacing) {
            error(
                body["spacing"], where + ".spacing",
                "must be >= the vehicle's min_spacing (" + std::to_string(plan_.vehicle.min_spacing) + " m)");
        }
        raw.spacing = spacing.value_or(0.0);
        raw.heading = number(body, "heading", where, false, -360.0, 360.0).value_or(0.0);
        const auto step = number(body, "step", where, false, 0.0, 1e6, true);
        if (step && *step < plan_.vehicle.min_spacing) {
            error(
                body["step"], where + ".step",
                "must be >= the vehicle's min_spacing (" + std::to_string(plan_.vehicle.min_spacing) + " m)");
        }
        raw.step = step.value_or(0.0);
        scans_[id] = std::move(raw);
    } else if (kind == "orbit") {
        if (!is_map(body, where))
            return;
        check_keys(body, where, {"name", "lat", "lon", "radius", "turns", "direction", "alt", "speed"});
        const auto id = add_node(NodeKind::Orbit, parent, path, mark);
        parse_leaf_common(body, plan_.nodes[id], where);
        if (auto p = lat_lon_fields(body, where, true)) {
            plan_.nodes[id].geo = *p;
            plan_.nodes[id].has_position = true;
        }
        RawOrbit raw;
        raw.radius = number(body, "radius", where, true, 0.0, 1e6, true).value_or(0.0);
        raw.turns = number(body, "turns", where, false, 0.0, 1e6, true).value_or(1.0);
        if (auto dir = text(body, "direction", where, false)) {
            if (*dir == "ccw") {
                raw.clockwise = false;
            } else if (*dir != "cw") {
                error(body["direction"], where + ".direction", "must be cw or ccw");
            }
        }
        if (raw.radius > 0.0 && 2.0 * kPi * raw.radius / plan_.vehicle.min_spacing < 3.0) {
            error(body["radius"], where + ".radius",
                  "too small for the vehicle's min_spacing (needs 3 points per turn at least)");
        }
        orbits_[id] = raw;
    } else if (kind == "speed") {
        const auto id = add_node(NodeKind::Speed, parent, path, mark);
        if (body.IsScalar()) {
            plan_.nodes[id].speed = number_value(body, where, 0.0, 1000.0, true);
        } else if (is_map(body, where)) {
            check_keys(body, where, {"name", "value"});
            if (auto name = text(body, "name", where, false))
                plan_.nodes[id].name = *name;
            plan_.nodes[id].speed = number(body, "value", where, true, 0.0, 1000.0, true);
        }
    } else if (kind == "repeat") {
        if (!is_map(body, where))
            return;
        check_keys(body, where, {"name", "count", "elements"});
        const auto id = add_node(NodeKind::Repeat, parent, path, mark);
        if (auto name = text(body, "name", where, false))
            plan_.nodes[id].name = *name;
        const YAML::Node count = body["count"];
        if (!count.IsDefined()) {
            error(body, where + ".count", "missing required field (a number or 'forever')");
        } else if (count.IsScalar() && count.Scalar() == "forever") {
            plan_.nodes[id].repeat_count.reset();
        } else if (auto c = number(body, "count", where, true, 1.0, 1e12)) {
            if (std::floor(*c) != *c) {
                error(count, where + ".count", "must be a whole number or 'forever'");
            }
            plan_.nodes[id].repeat_count = static_cast<std::uint64_t>(*c);
        }
        parse_elements(body["elements"], id, where + ".elements");
    } else if (kind == "block") {
        if (!is_map(body, where))
            return;
        check_keys(body, where, {"name", "elements"});
        const auto id = add_node(NodeKind::Block, parent, path, mark);
        if (auto name = text(body, "name", where, true))
            plan_.nodes[id].name = *name;
        parse_elements(body["elements"], id, where + ".elements");
    } else if (kind == "goto") {
        const auto id = add_node(NodeKind::Goto, parent, path, mark);
        if (body.IsScalar() && !body.Scalar().empty()) {
            plan_.nodes[id].goto_target_name = body.Scalar();
        } else if (is_map(body, where)) {
            check_keys(body, where, {"name", "target"});
            if (auto name = text(body, "name", where, false))
                plan_.nodes[id].name = *name;
            if (auto target = text(body, "target", where, true))
                plan_.nodes[id].goto_target_name = *target;
        }
    } else {
        static constexpr std::string_view kKinds[] = {"waypoint", "hold",   "scan",  "orbit",
                                                      "speed",    "repeat", "block", "goto"};
        error(item.begin()->first, where,
              "unknown element" + did_you_mean(kind, kKinds) +
                  " (expected one of: waypoint, hold, scan, orbit, speed, repeat, block, goto)");
    }
}

void Loader::parse_elements(const YAML::Node& list, std::uint32_t parent, const std::string& path) {
    if (!list.IsDefined() || !list.IsSequence() || list.size() == 0) {
        error(list.IsDefined() ? mark_of(list) : plan_.nodes[parent].mark, path,
              "must be a non-empty list of elements");
        return;
    }
    for (std::size_t i = 0; i < list.size(); ++i)
        parse_element(list[i], parent, path + "[" + std::to_string(i) + "]");
}

void Loader::parse_blocks(const YAML::Node& list, const std::string& path) {
    plan_.blocks_list = add_node(NodeKind::ElementList, kNoNode, path, mark_of(list));
    if (!list.IsDefined())
        return;
    if (!list.IsSequence()) {
        error(list, path, "must be a list of named blocks");
        return;
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string where = path + "[" + std::to_string(i) + "]";
        const YAML::Node b = list[i];
        if (!is_map(b, where))
            continue;
        check_keys(b, where, {"name", "elements"});
        const auto id = add_node(NodeKind::Block, plan_.blocks_list, where, mark_of(b));
        if (auto name = text(b, "name", where, true))
            plan_.nodes[id].name = *name;
        parse_elements(b["elements"], id, where + ".elements");
    }
}

void Loader::parse_vehicle(const YAML::Node& v, const std::string& path) {
    if (!v.IsDefined())
        return;
    if (!is_map(v, path))
        return;
    check_keys(v, path, {"type", "min_spacing", "arrival_radius", "cruise_speed"});
    if (auto type = text(v, "type", path, false)) {
        if (auto d = VehicleProfile::defaults_for(*type)) {
            plan_.vehicle = *d;
        } else {
            error(v["type"], path + ".type", "unknown vehicle type (expected rover, boat, plane or copter)");
        }
    }
    if (auto x = number(v, "min_spacing", path, false, 0.1, 1e5))
        plan_.vehicle.min_spacing = *x;
    if (auto x = number(v, "arrival_radius", path, false, 0.0, 1e5, true))
        plan_.vehicle.arrival_radius = *x;
    if (auto x = number(v, "cruise_speed", path, false, 0.0, 1000.0, true)) {
        plan_.vehicle.cruise_speed = *x;
        plan_.vehicle.cruise_speed_given = true;
    }
}

std::optional<Reaction> Loader::parse_reaction(const YAML::Node& node, const std::string& path) {
    Reaction r;
    const auto action = text(node, "action", path, true);
    if (!action)
        return std::nullopt;
    if (*action == "hold") {
        r.action = ReactionAction::Hold;
    } else if (*action == "return_home") {
        r.action = ReactionAction::ReturnHome;
    } else if (*action == "continue") {
        r.action = ReactionAction::Continue;
    } else if (*action == "goto") {
        r.action = ReactionAction::GotoBlock;
        if (auto t = text(node, "target", path, true))
            r.target = *t;
        reaction_paths_.emplace_back(path + ".target", mark_of(node));
    } else {
        error(node["action"], path + ".action", "must be one of: hold, return_home, continue, goto");
        return std::nullopt;
    }
    if (r.action != ReactionAction::GotoBlock && node["target"].IsDefined()) {
        error(node["target"], path + ".target", "only allowed with action: goto");
    }
    return r;
}

void Loader::parse_reactions(const YAML::Node& r, const std::string& path) {
    if (!r.IsDefined())
        return;
    if (!is_map(r, path))
        return;
    check_keys(r, path, {"link_loss", "low_battery", "geofence"});
    if (const YAML::Node n = r["link_loss"]; n.IsDefined() && is_map(n, path + ".link_loss")) {
        check_keys(n, path + ".link_loss", {"after", "action", "target"});
        plan_.reactions.link_loss_seconds =
            number(n, "after", path + ".link_loss", true, 0.0, 86400.0, true).value_or(30.0);
        plan_.reactions.link_loss = parse_reaction(n, path + ".link_loss");
    }
    if (const YAML::Node n = r["low_battery"]; n.IsDefined() && is_map(n, path + ".low_battery")) {
        check_keys(n, path + ".low_battery", {"below", "action", "target"});
        plan_.reactions.low_battery_percent =
            number(n, "below", path + ".low_battery", true, 0.0, 100.0, true).value_or(20.0);
        plan_.reactions.low_battery = parse_reaction(n, path + ".low_battery");
    }
    if (const YAML::Node n = r["geofence"]; n.IsDefined() && is_map(n, path + ".geofence")) {
        check_keys(n, path + ".geofence", {"action", "target"});
        plan_.reactions.geofence = parse_reaction(n, path + ".geofence");
    }
}

void Loader::parse_plan(const YAML::Node& p) {
    const std::string path = "plan";
    check_keys(
        p, path,
        {"name", "vehicle", "reference", "home", "no_fly", "geofence", "reactions", "elements", "blocks"});
    if (auto name = text(p, "name", path, true))
        plan_.name = *name;
    // The vehicle first: its min_spacing bounds the scans and orbits below.
    parse_vehicle(p["vehicle"], path + ".vehicle");
    if (const YAML::Node r = p["reference"]; r.IsDefined() && is_map(r, path + ".reference")) {
        check_keys(r, path + ".reference", {"lat", "lon"});
        reference_ = lat_lon_fields(r, path + ".reference", true);
    }
    if (const YAML::Node h = p["home"]; h.IsDefined() && is_map(h, path + ".home")) {
        check_keys(h, path + ".home", {"lat", "lon"});
        plan_.home = lat_lon_fields(h, path + ".home", true);
    }
    if (const YAML::Node z = p["no_fly"]; z.IsDefined()) {
        if (!z.IsSequence()) {
            error(z, path + ".no_fly", "must be a list of zones");
        } else {
            for (std::size_t i = 0; i < z.size(); ++i) {
                const std::string where = path + ".no_fly[" + std::to_string(i) + "]";
                if (!is_map(z[i], where))
                    continue;
                check_keys(z[i], where, {"name", "buffer", "polygon"});
                NoFlyZone zone;
                zone.mark = mark_of(z[i]);
                zone.name = text(z[i], "name", where, false).value_or("no_fly[" + std::to_string(i) + "]");
                zone.buffer = number(z[i], "buffer", where, false, 0.0, 1e5).value_or(0.0);
                if (!z[i]["polygon"].IsDefined()) {
                    error(z[i], where + ".polygon", "missing required field");
                } else if (auto poly = polygon(z[i]["polygon"], where + ".polygon")) {
                    zone.polygon = *poly;
                    plan_.no_fly.push_back(std::move(zone));
                }
            }
        }
    }
    if (const YAML::Node g = p["geofence"]; g.IsDefined()) {
        if (auto poly = polygon(g, path + ".geofence"))
            plan_.geofence = *poly;
    }
    parse_reactions(p["reactions"], path + ".reactions");
    plan_.main_list = add_node(NodeKind::ElementList, kNoNode, path + ".elements", mark_of(p));
    parse_elements(p["elements"], plan_.main_list, path + ".elements");
    parse_blocks(p["blocks"], path + ".blocks");
}

void Loader::finish_geometry() {
    plan_.frame = LocalFrame(reference_.value_or(first_coordinate_.value_or(LatLon{})));
    const LocalFrame& f = plan_.frame;
    auto to_local = [&](const std::vector<LatLon>& poly) {
        std::vector<Enu> out;
        out.reserve(poly.size());
        for (auto p : poly)
            out.push_back(f.to_local(p));
        return out;
    };
    for (auto& zone : plan_.no_fly) {
        zone.local = to_local(zone.polygon);
        if (polygon_self_intersects(zone.local)) {
            error(zone.mark, "plan.no_fly." + zone.name, "polygon edges cross each other");
        }
    }
    plan_.geofence_local = to_local(plan_.geofence);
    for (auto& node : plan_.nodes) {
        if (node.has_position)
            node.pos = f.to_local(node.geo);
    }
    for (auto& [id, raw] : scans_) {
        Node& node = plan_.nodes[id];
        if (raw.polygon.empty() || !(raw.spacing > 0.0))
            continue;
        auto local = to_local(raw.polygon);
        if (polygon_self_intersects(local)) {
            error(node.mark, node.path + ".scan.polygon", "polygon edges cross each other");
            continue;
        }
        node.scan.emplace(std::move(local), raw.spacing, raw.heading, raw.step, plan_.vehicle.min_spacing);
        if (node.scan->too_many_lines()) {
            error(node.mark, node.path + ".scan.spacing",
                  "too small for this polygon (more than " + std::to_string(ScanPattern::kMaxLines) +
                      " lines)");
            node.scan.reset();
        } else if (node.scan->total_count() == 0) {
            error(node.mark, node.path + ".scan.polygon", "polygon has no area");
        }
    }
    for (auto& [id, raw] : orbits_) {
        Node& node = plan_.nodes[id];
        if (!(raw.radius > 0.0))
            continue;
        OrbitPattern o;
        o.centre = node.pos;
        o.radius = raw.radius;
        o.turns = raw.turns;
        o.clockwise = raw.clockwise;
        const double per_turn = std::floor(2.0 * kPi * raw.radius / plan_.vehicle.min_spacing);
        o.points_per_turn = static_cast<std::uint64_t>(std::clamp(per_turn, 3.0, 360.0));
        node.orbit = o;
    }
}

void Loader::resolve_names() {
    std::map<std::string, std::uint32_t> names;
    for (std::uint32_t i = 0; i < plan_.nodes.size(); ++i) {
        const Node& n = plan_.nodes[i];
        if (n.name.empty())
            continue;
        auto [it, inserted] = names.emplace(n.name, i);
        if (!inserted) {
            error(n.mark, n.path + ".name",
                  "duplicate name '" + n.name + "' (first used at " + plan_.nodes[it->second].path + ")");
        }
    }
    for (auto& n : plan_.nodes) {
        if (n.kind != NodeKind::Goto || n.goto_target_name.empty())
            continue;
        auto it = names.find(n.goto_target_name);
        if (it == names.end()) {
            error(n.mark, n.path + ".goto",
                  "target '" + n.goto_target_name + "' is not the name of any element");
        } else {
            n.goto_target = it->second;
        }
    }
    Reaction* reactions[] = {plan_.reactions.link_loss ? &*plan_.reactions.link_loss : nullptr,
                             plan_.reactions.low_battery ? &*plan_.reactions.low_battery : nullptr,
                             plan_.reactions.geofence ? &*plan_.reactions.geofence : nullptr};
    std::size_t goto_index = 0;
    for (Reaction* r : reactions) {
        if (r == nullptr || r->action != ReactionAction::GotoBlock)
            continue;
        const auto& [path, mark] = reaction_paths_.at(goto_index++);
        auto it = names.find(r->target);
        if (r->target.empty())
            continue;
        if (it == names.end()) {
            error(mark, path, "target '" + r->target + "' is not the name of any element");
        } else {
            r->target_node = it->second;
        }
    }
}

void Loader::derive_counts(const LoadOptions& options) {
    // Children come after their parents in the vector, so a reverse walk is a post-order walk.
    const std::uint64_t cap = options.max_finite_waypoints;
    for (std::size_t i = plan_.nodes.size(); i-- > 0;) {
        Node& n = plan_.nodes[i];
        switch (n.kind) {
            case NodeKind::Waypoint:
            case NodeKind::Hold:
                n.count = 1;
                break;
            case NodeKind::Speed:
                n.count = 0;
                break;
            case NodeKind::Scan:
                n.count = n.scan ? n.scan->total_count() : 0;
                break;
            case NodeKind::Orbit:
                n.count = n.orbit ? n.orbit->count() : 0;
                break;
            case NodeKind::Goto:
                n.count.reset();
                break;
            case NodeKind::ElementList:
            case NodeKind::Block:
            case NodeKind::Repeat: {
                std::optional<std::uint64_t> sum = 0;
                for (auto c : n.children) {
                    const auto& cc = plan_.nodes[c].count;
                    if (!cc || !sum || *sum + *cc > cap) {
                        if (cc && sum)
                            error(n.mark, n.path,
                                  "expands to more than " + std::to_string(cap) + " waypoints");
                        sum.reset();
                        break;
                    }
                    *sum += *cc;
                }
                if (n.kind == NodeKind::Repeat) {
                    if (sum && *sum == 0 && !n.repeat_count) {
                        error(n.mark, n.path + ".repeat", "repeats forever but produces no waypoints");
                    }
                    if (!n.repeat_count || !sum) {
                        sum.reset();
                    } else if (*sum != 0 && *n.repeat_count > cap / *sum) {
                        error(n.mark, n.path, "expands to more than " + std::to_string(cap) + " waypoints");
                        sum.reset();
                    } else {
                        *sum *= *n.repeat_count;
                    }
                }
                n.count = sum;
                break;
            }
        }
    }
}

LoadResult Loader::run(const YAML::Node& doc, const LoadOptions& options) {
    if (!doc.IsMap() || !doc["plan"].IsDefined()) {
        error(doc, "", "the document must be a mapping with a top-level 'plan' key");
    } else {
        check_keys(doc, "", {"plan"});
        if (is_map(doc["plan"], "plan"))
            parse_plan(doc["plan"]);
    }
    if (errors_.empty()) {
        finish_geometry();
        resolve_names();
        derive_counts(options);
    }
    if (errors_.empty())
        check_legs(plan_, options.leg_check_limit, errors_);
    LoadResult result;
    if (errors_.empty()) {
        result.plan = std::make_shared<const Plan>(std::move(plan_));
    } else {
        result.errors = std::move(errors_);
    }
    return result;
}

}  // namespace

LoadResult load_plan_text(std::string_view text, const std::string& source_name, const LoadOptions& options) {
    if (text.size() > kMaxPlanTextBytes) {
        LoadResult r;
        r.errors.push_back(
            {source_name, 0, 0, "", "plan larger than " + std::to_string(kMaxPlanTextBytes) + " bytes"});
        return r;
    }
    Loader loader(source_name, options.max_elements, options.default_vehicle);
    YAML::Node doc;
    try {
        doc = YAML::Load(std::string(text));
    } catch (const YAML::Exception& e) {
        LoadResult r;
        r.errors.push_back(
            {source_name, e.mark.line + 1, e.mark.column + 1, "", "YAML syntax error: " + e.msg});
        return r;
    }
    try {
        return loader.run(doc, options);
    } catch (const YAML::Exception& e) {
        // yaml-cpp throws for shapes our checks did not anticipate; still a located, clean rejection.
        LoadResult r;
        r.errors.push_back({source_name, e.mark.line + 1, e.mark.column + 1, "", "malformed plan: " + e.msg});
        return r;
    }
}

LoadResult load_plan_file(const std::string& path, const LoadOptions& options) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        LoadResult r;
        r.errors.push_back({path, 0, 0, "", "cannot open the file"});
        return r;
    }
    std::string text(kMaxPlanTextBytes + 1, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    return load_plan_text(text, path, options);
}

}  // namespace airseg::flightplan
