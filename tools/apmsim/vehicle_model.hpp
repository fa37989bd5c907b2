#pragma once
// A kinematic car on a flat earth around its start point: position, heading, speed. It steers toward a
// target at a limited turn rate and reaches its desired speed at a limited acceleration; in manual modes
// the steering and throttle sticks drive it directly. Good enough to make the mission logic behave like
// the real vehicle's (distances, times, passing a point), not a dynamics model.
#include <cstdint>
#include <optional>

#include "base/time.hpp"

namespace airseg::apmsim {

struct GeoPoint {
    double lat = 0;  // degrees
    double lon = 0;  // degrees
};

/// Metres between two points (equirectangular; exact enough over a few kilometres).
double distance_m(const GeoPoint& a, const GeoPoint& b);
/// Bearing from a to b, radians clockwise from north, in [0, 2π).
double bearing_rad(const GeoPoint& a, const GeoPoint& b);
/// The point `metres` from `p` along `bearing`.
GeoPoint offset(const GeoPoint& p, double bearing, double metres);

struct DriveLimits {
    double max_accel = 2.0;       // m/s²
    double max_turn_rate = 3.0;   // rad/s
    double lateral_accel = 19.6;  // m/s², the TURN_MAX_G limit
    double max_speed = 10.0;      // m/s at full throttle in manual modes
};

class VehicleModel {
  public:
    explicit VehicleModel(GeoPoint start, double heading = 0) : pos_(start), heading_(heading) {}

    /// Drives toward `target` at `speed` for `dt` seconds.
    void drive_to(const GeoPoint& target, double speed, double dt, const DriveLimits& limits);
    /// Sticks in [-1, 1]: steering (right positive) and throttle (forward positive).
    void drive_manual(double steering, double throttle, double dt, const DriveLimits& limits);
    /// Slows to a stop.
    void stop(double dt, const DriveLimits& limits);

    const GeoPoint& position() const { return pos_; }
    double heading() const { return heading_; }  // radians from north
    double speed() const { return speed_; }      // m/s, forward
    double turn_rate() const { return turn_rate_; }
    double throttle() const { return throttle_; }  // [-1, 1], last commanded
    double steering() const { return steering_; }  // [-1, 1], last commanded
    double odometer() const { return odometer_; }  // metres driven

  private:
    void integrate(double dt);
    void approach_speed(double desired, double dt, const DriveLimits& limits);

    GeoPoint pos_;
    double heading_ = 0;
    double speed_ = 0;
    double turn_rate_ = 0;
    double throttle_ = 0;
    double steering_ = 0;
    double odometer_ = 0;
};

}  // namespace airseg::apmsim
