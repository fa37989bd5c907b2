#include "services/flightplan/plan_parser.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <sstream>

#include "services/common/nearest_word.hpp"
#include "services/flightplan/plan_validator.hpp"

namespace airseg::flightplan {

namespace {

SourceMark mark_of(const YRef& node) {
    if (!node.IsDefined()) {
        return {};
    }
    const YAML::Mark m = node.Mark();
    if (m.line < 0) {
        return {};
    }
    return {m.line + 1, m.column + 1};
}

}  // namespace

PlanParser::PlanParser(std::string file, std::size_t max_elements, VehicleProfile vehicle)
    : file_(std::move(file)), max_elements_(max_elements) {
    plan_.source_file = file_;
    plan_.vehicle = std::move(vehicle);
}

void PlanParser::error(const YRef& at, const std::string& path, std::string message) {
    error(mark_of(at), path, std::move(message));
}

bool PlanParser::is_map(const YRef& node, const std::string& path) {
    if (node.IsMap()) {
        return true;
    }
    error(node, path, "must be a mapping");
    return false;
}

void PlanParser::check_keys(const YRef& map, const std::string& path,
                            std::initializer_list<std::string_view> allowed) {
    for (std::size_t i = 0; i < map.size(); ++i) {
        const std::string key = map.key(i).Scalar();
        bool known = false;
        for (auto a : allowed) {
            known = known || key == a;
        }
        if (!known) {
            std::string list;
            for (auto a : allowed) {
                list += (list.empty() ? "" : ", ") + std::string(a);
            }
            error(map.key(i), path + "." + key,
                  "unknown field" + did_you_mean(key, allowed) + " (expected one of: " + list + ")");
        }
    }
}

std::optional<double> PlanParser::number(const YRef& map, const char* key, const std::string& path,
                                         bool required, double lo, double hi, bool lo_open) {
    const YRef value = map[key];
    const std::string where = path + "." + key;
    if (!value.IsDefined() || value.IsNull()) {
        if (required) {
            error(map, where, "missing required field");
        }
        return std::nullopt;
    }
    return number_value(value, where, lo, hi, lo_open);
}

std::optional<double> PlanParser::number_value(const YRef& value, const std::string& where, double lo,
                                               double hi, bool lo_open) {
    double v = 0.0;
    if (!value.IsScalar() || !decode_double(value, v) || !std::isfinite(v)) {
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

std::optional<std::string> PlanParser::text(const YRef& map, const char* key, const std::string& path,
                                            bool required) {
    const YRef value = map[key];
    if (!value.IsDefined() || value.IsNull()) {
        if (required) {
            error(map, path + "." + key, "missing required field");
        }
        return std::nullopt;
    }
    if (!value.IsScalar() || value.Scalar().empty()) {
        error(value, path + "." + key, "must be a non-empty string");
        return std::nullopt;
    }
    if (value.Scalar().size() > kMaxTextBytes) {
        // Names are shown in every status document and every reply about the plan.
        error(value, path + "." + key,
              "longer than the " + std::to_string(kMaxTextBytes) + " bytes allowed (" +
                  std::to_string(value.Scalar().size()) + ")");
        return std::nullopt;
    }
    return value.Scalar();
}

void PlanParser::note_coordinate(LatLon p, const YRef& at, const std::string& path) {
    if (!first_coordinate_) {
        first_coordinate_ = p;
    }
    // The reference is known by now: plan.reference is read before any other position, and without it the
    // first position is the reference.
    const LatLon reference = reference_.value_or(*first_coordinate_);
    const bool polar = std::abs(p.lat) > kMaxFrameLatitude;
    const double reach = great_circle_distance(reference, p);
    if (!polar && reach <= kMaxFrameReachMetres) {
        return;
    }
    if (out_of_frame_++ > 0) {
        return;  // the first one is located; finish() counts the rest
    }
    std::ostringstream msg;
    msg.precision(7);
    if (polar) {
        msg << "latitude " << p.lat << " is beyond " << kMaxFrameLatitude
            << " degrees: the plan's local frame does not reach the poles";
    } else {
        msg << "is " << std::llround(reach / 1000.0) << " km from the plan's reference (" << reference.lat
            << ", " << reference.lon << "): every position must lie within " << kMaxFrameReachMetres / 1000.0
            << " km of it, the reach of the plan's local frame (set plan.reference near the plan's middle)";
    }
    out_of_frame_error_ = errors_.size();
    error(at, path, msg.str());
}

std::optional<LatLon> PlanParser::lat_lon_fields(const YRef& map, const std::string& path, bool required) {
    const bool has_lat = map["lat"].IsDefined(), has_lon = map["lon"].IsDefined();
    if (!required && !has_lat && !has_lon) {
        return std::nullopt;
    }
    const auto lat = number(map, "lat", path, true, -90.0, 90.0);
    const auto lon = number(map, "lon", path, true, -180.0, 180.0);
    if (!lat || !lon) {
        return std::nullopt;
    }
    note_coordinate({*lat, *lon}, map, path);
    return LatLon{*lat, *lon};
}

std::optional<LatLon> PlanParser::point(const YRef& node, const std::string& path) {
    if (!node.IsSequence() || node.size() != 2) {
        error(node, path, "must be a [lat, lon] pair");
        return std::nullopt;
    }
    double lat = 0.0, lon = 0.0;
    if (!decode_double(node[0], lat) || !std::isfinite(lat) || lat < -90.0 || lat > 90.0) {
        error(node[0], path + "[0]", "latitude must be a number between -90 and 90");
        return std::nullopt;
    }
    if (!decode_double(node[1], lon) || !std::isfinite(lon) || lon < -180.0 || lon > 180.0) {
        error(node[1], path + "[1]", "longitude must be a number between -180 and 180");
        return std::nullopt;
    }
    note_coordinate({lat, lon}, node, path);
    return LatLon{lat, lon};
}

std::optional<std::vector<LatLon>> PlanParser::polygon(const YRef& node, const std::string& path) {
    if (!node.IsSequence() || node.size() < 3) {
        error(node, path, "must be a list of at least 3 [lat, lon] vertices");
        return std::nullopt;
    }
    if (node.size() > kMaxPolygonVertices) {
        // Every scan line and every leg checked against a zone crosses each edge.
        error(node, path,
              "has " + std::to_string(node.size()) + " vertices, more than the " +
                  std::to_string(kMaxPolygonVertices) + " allowed");
        return std::nullopt;
    }
    std::vector<LatLon> out;
    bool ok = true;
    for (std::size_t i = 0; i < node.size(); ++i) {
        const auto p = point(node[i], path + "[" + std::to_string(i) + "]");
        ok = ok && p.has_value();
        if (p) {
            out.push_back(*p);
        }
    }
    if (!ok) {
        return std::nullopt;
    }
    return out;
}

std::uint32_t PlanParser::add_node(NodeKind kind, std::uint32_t parent, SourceMark mark) {
    const auto id = static_cast<std::uint32_t>(plan_.nodes.size());
    Node& node = plan_.nodes.emplace_back();
    node.kind = kind;
    node.parent = parent;
    node.mark = mark;
    if (parent != kNoNode) {
        plan_.extra_for(parent).children.push_back(id);
    }
    // Scans and orbits get their patterns at the end; their extras are made now, in id order.
    if (kind == NodeKind::Scan || kind == NodeKind::Orbit) {
        plan_.extra_for(id);
    }
    return id;
}

void PlanParser::set_name(std::uint32_t id, std::optional<std::string> name) {
    if (name) {
        plan_.extra_for(id).name = std::move(*name);
    }
}

void PlanParser::set_optional(std::uint32_t id, std::optional<double> NodeExtra::*field,
                              std::optional<double> v) {
    if (v) {
        plan_.extra_for(id).*field = v;
    }
}

void PlanParser::parse_leaf_common(const YRef& body, std::uint32_t id, const std::string& path) {
    set_name(id, text(body, "name", path, false));
    if (auto alt = number(body, "alt", path, false, -1000.0, 100000.0)) {
        plan_.nodes[id].has_alt = true;
        plan_.nodes[id].alt_value = *alt;
    }
    set_optional(id, &NodeExtra::speed, number(body, "speed", path, false, 0.0, 1000.0, true));
}

void PlanParser::parse_element(const YRef& item, std::uint32_t parent, const std::string& path) {
    if (auto list = element_head(item, parent, path)) {
        parse_elements(list->body["elements"], list->id, list->path);
    }
}

std::optional<PlanParser::ListTarget> PlanParser::element_head(const YRef& item, std::uint32_t parent,
                                                               const std::string& path) {
    // YAML aliases can make a small file describe an exponential number of elements.
    if (plan_.nodes.size() >= max_elements_) {
        if (!too_many_elements_) {
            error(item, path, "more than " + std::to_string(max_elements_) + " elements");
        }
        too_many_elements_ = true;
        return std::nullopt;
    }
    if (!item.IsMap() || item.size() != 1) {
        error(item, path,
              "an element is a mapping with exactly one of: waypoint, hold, scan, orbit, speed, repeat, "
              "block, goto");
        return std::nullopt;
    }
    const std::string kind = item.key(0).Scalar();
    const YRef body = item.value(0);
    const std::string where = path + "." + kind;
    const SourceMark mark = mark_of(item);

    if (kind == "waypoint") {
        if (!is_map(body, where)) {
            return std::nullopt;
        }
        check_keys(body, where, {"name", "lat", "lon", "alt", "speed", "radius"});
        const auto id = add_node(NodeKind::Waypoint, parent, mark);
        parse_leaf_common(body, id, where);
        set_optional(id, &NodeExtra::arrival_radius,
                     number(body, "radius", where, false, 0.0, 100000.0, true));
        if (auto p = lat_lon_fields(body, where, true)) {
            plan_.nodes[id].geo = *p;
            plan_.nodes[id].has_position = true;
        }
    } else if (kind == "hold") {
        if (!is_map(body, where)) {
            return std::nullopt;
        }
        check_keys(body, where, {"name", "lat", "lon", "alt", "radius", "seconds", "until_released"});
        const auto id = add_node(NodeKind::Hold, parent, mark);
        parse_leaf_common(body, id, where);
        set_optional(id, &NodeExtra::arrival_radius,
                     number(body, "radius", where, false, 0.0, 100000.0, true));
        if (auto p = lat_lon_fields(body, where, false)) {
            plan_.nodes[id].geo = *p;
            plan_.nodes[id].has_position = true;
        }
        set_optional(id, &NodeExtra::hold_seconds,
                     number(body, "seconds", where, false, 0.0, 7.0 * 86400.0, true));
        bool until_released = false;
        if (const YRef u = body["until_released"]; u.IsDefined()) {
            if (!decode_bool(u, until_released)) {
                error(u, where + ".until_released", "must be true or false");
            }
        }
        if (body["seconds"].IsDefined() == until_released) {
            error(body, where, "needs exactly one of: seconds, until_released: true");
        }
    } else if (kind == "scan") {
        if (!is_map(body, where)) {
            return std::nullopt;
        }
        check_keys(body, where,
                   {"name", "polygon", "rectangle", "spacing", "heading", "step", "alt", "speed"});
        const auto id = add_node(NodeKind::Scan, parent, mark);
        parse_leaf_common(body, id, where);
        RawScan raw;
        const YRef poly = body["polygon"], rect = body["rectangle"];
        if (poly.IsDefined() == rect.IsDefined()) {
            error(body, where, "needs exactly one of: polygon, rectangle");
        } else if (poly.IsDefined()) {
            if (auto p = polygon(poly, where + ".polygon")) {
                raw.polygon = *p;
            }
        } else if (is_map(rect, where + ".rectangle")) {
            check_keys(rect, where + ".rectangle", {"sw", "ne"});
            const YRef sw_node = rect["sw"], ne_node = rect["ne"];
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
        if (!is_map(body, where)) {
            return std::nullopt;
        }
        check_keys(body, where, {"name", "lat", "lon", "radius", "turns", "direction", "alt", "speed"});
        const auto id = add_node(NodeKind::Orbit, parent, mark);
        parse_leaf_common(body, id, where);
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
        const auto id = add_node(NodeKind::Speed, parent, mark);
        if (body.IsScalar()) {
            set_optional(id, &NodeExtra::speed, number_value(body, where, 0.0, 1000.0, true));
        } else if (is_map(body, where)) {
            check_keys(body, where, {"name", "value"});
            set_name(id, text(body, "name", where, false));
            set_optional(id, &NodeExtra::speed, number(body, "value", where, true, 0.0, 1000.0, true));
        }
    } else if (kind == "repeat") {
        if (!is_map(body, where)) {
            return std::nullopt;
        }
        check_keys(body, where, {"name", "count", "elements"});
        const auto id = add_node(NodeKind::Repeat, parent, mark);
        set_name(id, text(body, "name", where, false));
        const YRef count = body["count"];
        if (!count.IsDefined()) {
            error(body, where + ".count", "missing required field (a number or 'forever')");
        } else if (count.IsScalar() && count.Scalar() == "forever") {
            plan_.extra_for(id).repeat_count.reset();
        } else if (auto c = number(body, "count", where, true, 1.0, 1e12)) {
            if (std::floor(*c) != *c) {
                error(count, where + ".count", "must be a whole number or 'forever'");
            }
            plan_.extra_for(id).repeat_count = static_cast<std::uint64_t>(*c);
        }
        return ListTarget{id, where + ".elements", body};
    } else if (kind == "block") {
        if (!is_map(body, where)) {
            return std::nullopt;
        }
        check_keys(body, where, {"name", "elements"});
        const auto id = add_node(NodeKind::Block, parent, mark);
        set_name(id, text(body, "name", where, true));
        return ListTarget{id, where + ".elements", body};
    } else if (kind == "goto") {
        const auto id = add_node(NodeKind::Goto, parent, mark);
        if (body.IsScalar() && !body.Scalar().empty()) {
            plan_.extra_for(id).goto_target_name = body.Scalar();
        } else if (is_map(body, where)) {
            check_keys(body, where, {"name", "target"});
            set_name(id, text(body, "name", where, false));
            if (auto target = text(body, "target", where, true)) {
                plan_.extra_for(id).goto_target_name = *target;
            }
        }
    } else {
        static constexpr std::string_view kKinds[] = {"waypoint", "hold",   "scan",  "orbit",
                                                      "speed",    "repeat", "block", "goto"};
        error(item.key(0), where,
              "unknown element" + did_you_mean(kind, kKinds) +
                  " (expected one of: waypoint, hold, scan, orbit, speed, repeat, block, goto)");
    }
    return std::nullopt;
}

void PlanParser::empty_list(const YRef& list, std::uint32_t parent, const std::string& path) {
    error(list.IsDefined() ? mark_of(list) : plan_.nodes[parent].mark, path,
          "must be a non-empty list of elements");
}

void PlanParser::parse_elements(const YRef& list, std::uint32_t parent, const std::string& path) {
    if (!list.IsDefined() || !list.IsSequence() || list.size() == 0) {
        empty_list(list, parent, path);
        return;
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
        parse_element(list[i], parent, path + "[" + std::to_string(i) + "]");
    }
}

void PlanParser::begin_blocks(const YRef& list) {
    plan_.blocks_list = add_node(NodeKind::ElementList, kNoNode, mark_of(list));
}

void PlanParser::parse_blocks(const YRef& list, const std::string& path) {
    begin_blocks(list);
    if (!list.IsDefined()) {
        return;
    }
    if (!list.IsSequence()) {
        error(list, path, "must be a list of named blocks");
        return;
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
        parse_block(list[i], i);
    }
}

void PlanParser::parse_block(const YRef& b, std::size_t index) {
    if (auto list = block_head(b, index)) {
        parse_elements(list->body["elements"], list->id, list->path);
    }
}

std::optional<PlanParser::ListTarget> PlanParser::block_head(const YRef& b, std::size_t index) {
    const std::string where = "plan.blocks[" + std::to_string(index) + "]";
    if (!is_map(b, where)) {
        return std::nullopt;
    }
    check_keys(b, where, {"name", "elements"});
    const auto id = add_node(NodeKind::Block, plan_.blocks_list, mark_of(b));
    set_name(id, text(b, "name", where, true));
    return ListTarget{id, where + ".elements", b};
}

void PlanParser::parse_vehicle(const YRef& v, const std::string& path) {
    if (!v.IsDefined()) {
        return;
    }
    if (!is_map(v, path)) {
        return;
    }
    check_keys(v, path, {"type", "min_spacing", "arrival_radius", "cruise_speed"});
    if (auto type = text(v, "type", path, false)) {
        if (auto d = VehicleProfile::defaults_for(*type)) {
            plan_.vehicle = *d;
        } else {
            error(v["type"], path + ".type", "unknown vehicle type (expected rover, boat, plane or copter)");
        }
    }
    if (auto x = number(v, "min_spacing", path, false, 0.1, 1e5)) {
        plan_.vehicle.min_spacing = *x;
    }
    if (auto x = number(v, "arrival_radius", path, false, 0.0, 1e5, true)) {
        plan_.vehicle.arrival_radius = *x;
    }
    if (auto x = number(v, "cruise_speed", path, false, 0.0, 1000.0, true)) {
        plan_.vehicle.cruise_speed = *x;
        plan_.vehicle.cruise_speed_given = true;
    }
}

std::optional<Reaction> PlanParser::parse_reaction(const YRef& node, const std::string& path) {
    Reaction r;
    const auto action = text(node, "action", path, true);
    if (!action) {
        return std::nullopt;
    }
    if (*action == "hold") {
        r.action = ReactionAction::Hold;
    } else if (*action == "return_home") {
        r.action = ReactionAction::ReturnHome;
    } else if (*action == "continue") {
        r.action = ReactionAction::Continue;
    } else if (*action == "goto") {
        r.action = ReactionAction::GotoBlock;
        if (auto t = text(node, "target", path, true)) {
            r.target = *t;
        }
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

void PlanParser::parse_reactions(const YRef& r, const std::string& path) {
    if (!r.IsDefined()) {
        return;
    }
    if (!is_map(r, path)) {
        return;
    }
    check_keys(r, path, {"link_loss", "low_battery", "geofence"});
    if (const YRef n = r["link_loss"]; n.IsDefined() && is_map(n, path + ".link_loss")) {
        check_keys(n, path + ".link_loss", {"after", "action", "target"});
        plan_.reactions.link_loss_seconds =
            number(n, "after", path + ".link_loss", true, 0.0, 86400.0, true).value_or(30.0);
        plan_.reactions.link_loss = parse_reaction(n, path + ".link_loss");
    }
    if (const YRef n = r["low_battery"]; n.IsDefined() && is_map(n, path + ".low_battery")) {
        check_keys(n, path + ".low_battery", {"below", "action", "target"});
        plan_.reactions.low_battery_percent =
            number(n, "below", path + ".low_battery", true, 0.0, 100.0, true).value_or(20.0);
        plan_.reactions.low_battery = parse_reaction(n, path + ".low_battery");
    }
    if (const YRef n = r["geofence"]; n.IsDefined() && is_map(n, path + ".geofence")) {
        check_keys(n, path + ".geofence", {"action", "target"});
        plan_.reactions.geofence = parse_reaction(n, path + ".geofence");
    }
}

void PlanParser::parse_plan(const YRef& p) {
    const ListTarget main = plan_head(p);
    parse_elements(p["elements"], main.id, main.path);
    parse_blocks(p["blocks"], "plan.blocks");
}

PlanParser::ListTarget PlanParser::begin_plan(const YRef& doc) {
    check_keys(doc, "", {"plan"});
    return plan_head(doc["plan"]);
}

PlanParser::ListTarget PlanParser::plan_head(const YRef& p) {
    const std::string path = "plan";
    check_keys(
        p, path,
        {"name", "vehicle", "reference", "home", "no_fly", "geofence", "reactions", "elements", "blocks"});
    if (auto name = text(p, "name", path, true)) {
        plan_.name = *name;
    }
    // The vehicle first: its min_spacing bounds the scans and orbits below.
    parse_vehicle(p["vehicle"], path + ".vehicle");
    if (const YRef r = p["reference"]; r.IsDefined() && is_map(r, path + ".reference")) {
        check_keys(r, path + ".reference", {"lat", "lon"});
        reference_ = lat_lon_fields(r, path + ".reference", true);
    }
    if (const YRef h = p["home"]; h.IsDefined() && is_map(h, path + ".home")) {
        check_keys(h, path + ".home", {"lat", "lon"});
        plan_.home = lat_lon_fields(h, path + ".home", true);
    }
    if (const YRef z = p["no_fly"]; z.IsDefined()) {
        if (!z.IsSequence()) {
            error(z, path + ".no_fly", "must be a list of zones");
        } else {
            for (std::size_t i = 0; i < z.size(); ++i) {
                const std::string where = path + ".no_fly[" + std::to_string(i) + "]";
                if (!is_map(z[i], where)) {
                    continue;
                }
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
    if (const YRef g = p["geofence"]; g.IsDefined()) {
        if (auto poly = polygon(g, path + ".geofence")) {
            plan_.geofence = *poly;
        }
    }
    parse_reactions(p["reactions"], path + ".reactions");
    plan_.main_list = add_node(NodeKind::ElementList, kNoNode, mark_of(p));
    return {plan_.main_list, path + ".elements", p};
}

void PlanParser::finish_geometry(std::uint64_t max_scan_work) {
    plan_.frame = LocalFrame(reference_.value_or(first_coordinate_.value_or(LatLon{})));
    const LocalFrame& f = plan_.frame;
    auto to_local = [&](const std::vector<LatLon>& poly) {
        std::vector<Enu> out;
        out.reserve(poly.size());
        for (auto p : poly) {
            out.push_back(f.to_local(p));
        }
        return out;
    };
    for (auto& zone : plan_.no_fly) {
        zone.local = to_local(zone.polygon);
        if (polygon_self_intersects(zone.local)) {
            error(zone.mark, "plan.no_fly." + zone.name, "polygon edges cross each other");
        }
    }
    plan_.geofence_local = to_local(plan_.geofence);
    for (auto& [id, raw] : scans_) {
        const SourceMark mark = plan_.nodes[id].mark;
        if (raw.polygon.empty() || !(raw.spacing > 0.0)) {
            continue;
        }
        auto local = to_local(raw.polygon);
        if (polygon_self_intersects(local)) {
            error(mark, plan_.element_path(id) + ".scan.polygon", "polygon edges cross each other");
            continue;
        }
        auto& scan = plan_.extra_for(id).scan;
        // Laying the scans out (counting their waypoints) crosses every line with every edge: a budget for
        // the whole plan, so that no plan keeps the service busy for long.
        const std::uint64_t budget = max_scan_work - std::min(max_scan_work, scan_work_);
        scan.emplace(std::move(local), raw.spacing, raw.heading, raw.step, plan_.vehicle.min_spacing, budget);
        if (scan->too_many_lines()) {
            const bool lines = scan->work() / static_cast<double>(scan->polygon().size()) >
                               static_cast<double>(ScanPattern::kMaxLines);
            error(mark, plan_.element_path(id) + ".scan.spacing",
                  lines ? "too small for this polygon (more than " + std::to_string(ScanPattern::kMaxLines) +
                              " lines)"
                        : "too small for this polygon: its lines times the polygon's edges (" +
                              std::to_string(std::llround(scan->work())) + ")" +
                              (scan_work_ > 0 ? ", with the plan's scans before it," : "") + " exceed the " +
                              std::to_string(max_scan_work) +
                              " line-edge crossings a plan's scans may take to lay out");
            scan.reset();
        } else if (scan->total_count() == 0) {
            error(mark, plan_.element_path(id) + ".scan.polygon", "polygon has no area");
        }
        if (scan) {
            scan_work_ += static_cast<std::uint64_t>(scan->work());
        }
    }
    for (auto& [id, raw] : orbits_) {
        if (!(raw.radius > 0.0)) {
            continue;
        }
        OrbitPattern o;
        o.centre = plan_.nodes[id].has_position ? plan_.local(id) : Enu{};
        o.radius = raw.radius;
        o.turns = raw.turns;
        o.clockwise = raw.clockwise;
        const double per_turn = std::floor(2.0 * kPi * raw.radius / plan_.vehicle.min_spacing);
        o.points_per_turn = static_cast<std::uint64_t>(std::clamp(per_turn, 3.0, 360.0));
        plan_.extra_for(id).orbit = o;
    }
}

void PlanParser::resolve_names() {
    std::map<std::string, std::uint32_t> names;
    for (std::uint32_t i = 0; i < plan_.nodes.size(); ++i) {
        const std::string& name = plan_.element_name(i);
        if (name.empty()) {
            continue;
        }
        auto [it, inserted] = names.emplace(name, i);
        if (!inserted) {
            error(plan_.nodes[i].mark, plan_.element_path(i) + ".name",
                  "duplicate name '" + name + "' (first used at " + plan_.element_path(it->second) + ")");
        }
    }
    for (std::uint32_t i = 0; i < plan_.nodes.size(); ++i) {
        if (plan_.nodes[i].kind != NodeKind::Goto || plan_.extra(i).goto_target_name.empty()) {
            continue;
        }
        NodeExtra& x = plan_.extra_for(i);
        auto it = names.find(x.goto_target_name);
        if (it == names.end()) {
            error(plan_.nodes[i].mark, plan_.element_path(i) + ".goto",
                  "target '" + x.goto_target_name + "' is not the name of any element");
        } else {
            x.goto_target = it->second;
        }
    }
    Reaction* reactions[] = {plan_.reactions.link_loss ? &*plan_.reactions.link_loss : nullptr,
                             plan_.reactions.low_battery ? &*plan_.reactions.low_battery : nullptr,
                             plan_.reactions.geofence ? &*plan_.reactions.geofence : nullptr};
    std::size_t goto_index = 0;
    for (Reaction* r : reactions) {
        if (r == nullptr || r->action != ReactionAction::GotoBlock) {
            continue;
        }
        const auto& [path, mark] = reaction_paths_.at(goto_index++);
        auto it = names.find(r->target);
        if (r->target.empty()) {
            continue;
        }
        if (it == names.end()) {
            error(mark, path, "target '" + r->target + "' is not the name of any element");
        } else {
            r->target_node = it->second;
        }
    }
}

void PlanParser::derive_counts(const LoadOptions& options) {
    // Children come after their parents in the deque, so a reverse walk is a post-order walk. Leaves derive
    // their counts (Plan::count); containers store theirs.
    const std::uint64_t cap = options.max_finite_waypoints;
    for (std::size_t i = plan_.nodes.size(); i-- > 0;) {
        const auto id = static_cast<std::uint32_t>(i);
        const Node& n = plan_.nodes[i];
        if (n.kind != NodeKind::ElementList && n.kind != NodeKind::Block && n.kind != NodeKind::Repeat) {
            continue;
        }
        NodeExtra& x = plan_.extra_for(id);
        std::optional<std::uint64_t> sum = 0;
        for (auto c : x.children) {
            const auto cc = plan_.count(c);
            if (!cc || !sum || *sum + *cc > cap) {
                if (cc && sum) {
                    error(n.mark, plan_.element_path(id),
                          "expands to more than " + std::to_string(cap) + " waypoints");
                }
                sum.reset();
                break;
            }
            *sum += *cc;
        }
        if (n.kind == NodeKind::Repeat) {
            if (sum && *sum == 0 && !x.repeat_count) {
                error(n.mark, plan_.element_path(id) + ".repeat",
                      "repeats forever but produces no waypoints");
            }
            if (!x.repeat_count || !sum) {
                sum.reset();
            } else if (*sum != 0 && *x.repeat_count > cap / *sum) {
                error(n.mark, plan_.element_path(id),
                      "expands to more than " + std::to_string(cap) + " waypoints");
                sum.reset();
            } else {
                *sum *= *x.repeat_count;
            }
        }
        x.count = sum;
        // Lists grow by doubling while loading; a long one would keep up to twice its size.
        x.children.shrink_to_fit();
    }
}

LoadResult PlanParser::run(const YRef& doc, const LoadOptions& options) {
    if (!doc.IsMap() || !doc["plan"].IsDefined()) {
        error(doc, "", "the document must be a mapping with a top-level 'plan' key");
    } else {
        check_keys(doc, "", {"plan"});
        if (is_map(doc["plan"], "plan")) {
            parse_plan(doc["plan"]);
        }
    }
    return finish(options);
}

LoadResult PlanParser::finish(const LoadOptions& options) {
    if (out_of_frame_ > 1) {
        errors_[out_of_frame_error_].message += " (and " + std::to_string(out_of_frame_ - 1) +
                                                " more position" + (out_of_frame_ > 2 ? "s" : "") + ")";
    }
    if (errors_.empty()) {
        finish_geometry(options.max_scan_work);
        resolve_names();
        derive_counts(options);
    }
    if (errors_.empty()) {
        check_legs(plan_, options.leg_check_limit, errors_);
    }
    LoadResult result;
    if (errors_.empty()) {
        result.plan = std::make_shared<const Plan>(std::move(plan_));
    } else {
        result.errors = std::move(errors_);
    }
    return result;
}

}  // namespace airseg::flightplan
