#pragma once
// The simulator's model of AR_WPNav's S-curve cornering (ArduPilot Rover 4.2 and later), in two formulas.
//
// AR_WPNav plans each leg to end at rest and blends the next leg in only within WP_RADIUS of the corner
// and while the lateral acceleration stays under ATC_TURN_MAX_G (SCurve::advance_target_along_track), so a
// sharp turn is taken slowly and a leg of no length, or no next leg at all, means a stop. The model: the
// corner is the arc tangent to both legs that starts and ends WP_RADIUS from the waypoint, radius
// WP_RADIUS / tan(turn / 2), driven at the speed whose lateral acceleration on it is ATC_TURN_MAX_G; the
// car brakes for it at ATC_ACCEL_MAX (the S-curve's acceleration) so that it is at that speed WP_RADIUS
// before the waypoint, or at rest on the waypoint for a stop.
#include <algorithm>
#include <cmath>
#include <numbers>

namespace airseg::apmsim {

/// The speed the car takes a corner at: `turn` the change of direction (radians, 0 straight on, π back the
/// way it came), no faster than `speed`.
inline double corner_speed(double turn, double speed, double lateral_accel, double wp_radius) {
    turn = std::abs(turn);
    if (turn < 1e-3) {
        return speed;
    }
    if (turn > std::numbers::pi - 1e-3) {
        return 0.0;
    }
    const double arc_radius = wp_radius / std::tan(turn / 2);
    return std::min(speed, std::sqrt(lateral_accel * arc_radius));
}

/// The fastest the car may go `distance` metres before a waypoint so that braking at `decel` brings it to
/// `corner` at `brake_to` metres from the waypoint (WP_RADIUS for a corner, 0 for a stop).
inline double approach_speed_limit(double corner, double distance, double brake_to, double decel) {
    const double room = std::max(0.0, distance - brake_to);
    return std::sqrt(corner * corner + 2 * decel * room);
}

}  // namespace airseg::apmsim
