#pragma once
// Sanity checks on what the autopilot reports, before it reaches status, the ground, the map or the flight
// plan: a position must be a place on Earth and come with a fix, a float must be a number. Pure functions.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

namespace airseg::autopilot::ardupilot {

/// Why a MAVLink position (degrees × 1e7) names no place; empty when it names one. ArduPilot sends 0, 0
/// before its first fix.
inline std::string position_problem(std::int32_t lat_e7, std::int32_t lon_e7) {
    char text[64];
    if (lat_e7 < -900'000'000 || lat_e7 > 900'000'000) {
        std::snprintf(text, sizeof text, "latitude %.7f outside ±90", lat_e7 * 1e-7);
        return text;
    }
    if (lon_e7 < -1'800'000'000 || lon_e7 > 1'800'000'000) {
        std::snprintf(text, sizeof text, "longitude %.7f outside ±180", lon_e7 * 1e-7);
        return text;
    }
    if (lat_e7 == 0 && lon_e7 == 0) {
        return "latitude and longitude 0 (no fix yet)";
    }
    return {};
}

/// GPS_RAW_INT fix types 0 (no GPS) and 1 (no fix) give no position.
inline bool gives_position(std::uint8_t fix_type) {
    return fix_type >= 2;
}

/// Empty when `value` is a number; else "MESSAGE.field is NaN" (or inf).
inline std::string float_problem(const char* where, float value) {
    if (std::isfinite(value)) {
        return {};
    }
    return std::string(where) + " is " + (std::isnan(value) ? "NaN" : (value > 0 ? "+inf" : "-inf"));
}

}  // namespace airseg::autopilot::ardupilot
