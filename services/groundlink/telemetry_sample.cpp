#include "services/groundlink/telemetry_sample.hpp"

#include <cmath>
#include <numbers>

namespace airseg::groundlink {

namespace {

int whole_degrees(double radians) {
    if (!std::isfinite(radians)) {
        return 0;
    }
    const double deg = std::round(radians * 180.0 / std::numbers::pi);
    return static_cast<int>(std::clamp(deg, -180.0, 180.0));
}

}  // namespace

protocol::Telemetry make_sample(const autopilot::Telemetry& t, const PlanProgressSample& plan) {
    protocol::Telemetry s;
    if (t.position) {
        s.lat_deg = t.position->lat;
        s.lon_deg = t.position->lon;
        s.alt_m = t.position->alt;
    }
    s.no_position = !t.position;
    s.ground_speed_mps = t.ground_speed;
    s.heading_deg = t.heading;
    s.roll_deg = whole_degrees(t.roll);
    s.pitch_deg = whole_degrees(t.pitch);
    s.battery_v = t.battery_voltage.value_or(0.0);
    s.battery_pct = t.battery_remaining;
    // GpsFix follows MAV_GPS_FIX_TYPE's order (NO_GPS, NO_FIX, 2D, 3D, DGPS, RTK_FLOAT, RTK_FIXED).
    s.gps_fix = static_cast<std::uint8_t>(t.gps_fix);
    s.satellites = static_cast<std::uint8_t>(std::min(t.satellites, 15u));
    s.vehicle_state = static_cast<std::uint8_t>(t.state);
    s.mode = t.custom_mode && *t.custom_mode < protocol::kModeUnknown
                 ? static_cast<std::uint8_t>(*t.custom_mode)
                 : protocol::kModeUnknown;
    s.plan_state = plan.plan_state;
    s.plan_element = plan.element;
    s.next_waypoint = plan.next_waypoint;
    return s;
}

}  // namespace airseg::groundlink
