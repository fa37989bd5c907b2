#include "tools/apmsim/vehicle_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace airseg::apmsim {

namespace {

constexpr double kMetresPerDegree = 111319.49;  // along a meridian, WGS84 equatorial radius
constexpr double kDegToRad = std::numbers::pi / 180.0;

double wrap_pi(double a) {
    while (a > std::numbers::pi) {
        a -= 2 * std::numbers::pi;
    }
    while (a < -std::numbers::pi) {
        a += 2 * std::numbers::pi;
    }
    return a;
}

}  // namespace

double distance_m(const GeoPoint& a, const GeoPoint& b) {
    const double north = (b.lat - a.lat) * kMetresPerDegree;
    const double east = (b.lon - a.lon) * kMetresPerDegree * std::cos((a.lat + b.lat) / 2 * kDegToRad);
    return std::hypot(north, east);
}

double bearing_rad(const GeoPoint& a, const GeoPoint& b) {
    const double north = (b.lat - a.lat) * kMetresPerDegree;
    const double east = (b.lon - a.lon) * kMetresPerDegree * std::cos((a.lat + b.lat) / 2 * kDegToRad);
    double bearing = std::atan2(east, north);
    if (bearing < 0) {
        bearing += 2 * std::numbers::pi;
    }
    return bearing;
}

GeoPoint offset(const GeoPoint& p, double bearing, double metres) {
    const double north = std::cos(bearing) * metres;
    const double east = std::sin(bearing) * metres;
    return GeoPoint{p.lat + north / kMetresPerDegree,
                    p.lon + east / (kMetresPerDegree * std::cos(p.lat * kDegToRad))};
}

void VehicleModel::approach_speed(double desired, double dt, const DriveLimits& limits) {
    const double step = limits.max_accel * dt;
    speed_ += std::clamp(desired - speed_, -step, step);
}

void VehicleModel::drive_to(const GeoPoint& target, double speed, double dt, const DriveLimits& limits) {
    const double error = wrap_pi(bearing_rad(pos_, target) - heading_);
    // A car turns no tighter than its lateral acceleration allows at the current speed.
    const double by_grip = limits.lateral_accel / std::max(std::abs(speed_), 0.5);
    const double max_rate = std::min(limits.max_turn_rate, by_grip);
    turn_rate_ = std::clamp(error / std::max(dt, 1e-3), -max_rate, max_rate);
    steering_ = max_rate > 0 ? turn_rate_ / max_rate : 0;
    // Slow down while the target is well off the nose, as the speed-turn gain does on the real rover.
    const double desired = std::abs(error) > std::numbers::pi / 2 ? speed * 0.5 : speed;
    approach_speed(desired, dt, limits);
    throttle_ = limits.max_speed > 0 ? std::clamp(desired / limits.max_speed, 0.0, 1.0) : 0;
    integrate(dt);
}

void VehicleModel::drive_manual(double steering, double throttle, double dt, const DriveLimits& limits) {
    steering_ = std::clamp(steering, -1.0, 1.0);
    throttle_ = std::clamp(throttle, -1.0, 1.0);
    const double by_grip = limits.lateral_accel / std::max(std::abs(speed_), 0.5);
    turn_rate_ = steering_ * std::min(limits.max_turn_rate, by_grip) * (speed_ >= 0 ? 1 : -1);
    approach_speed(throttle_ * limits.max_speed, dt, limits);
    integrate(dt);
}

void VehicleModel::stop(double dt, const DriveLimits& limits) {
    turn_rate_ = 0;
    steering_ = 0;
    throttle_ = 0;
    approach_speed(0, dt, limits);
    integrate(dt);
}

void VehicleModel::integrate(double dt) {
    heading_ = std::fmod(heading_ + turn_rate_ * dt + 2 * std::numbers::pi, 2 * std::numbers::pi);
    if (speed_ != 0) {
        pos_ = offset(pos_, heading_, speed_ * dt);
        odometer_ += std::abs(speed_) * dt;
    }
}

}  // namespace airseg::apmsim
