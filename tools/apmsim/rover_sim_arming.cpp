// RoverSim: arming as ArduPilot Rover 4.x does it (AP_Arming.cpp, Rover/AP_Arming_Rover.cpp, Rover/mode.h).
//  - ARMING_REQUIRE 0: always armed (AP_Arming::is_armed()); otherwise the board boots disarmed.
//  - The checks (skipped when ARMING_CHECK is 0): a check made to fail from the control socket, and the
//    position estimate in the modes that need a position (AUTO, GUIDED, RTL, SMART_RTL, LOITER).
//  - An arm attempt reports every failing check as "Arm: <reason>" (CRITICAL) and is answered
//    MAV_RESULT_FAILED; RTL, SMART_RTL and INITIALISING are not armable ("Arm: Mode not armable"), a check
//    the forced arm (param2 21196 or 2989) skips like the others.
//  - While disarmed, AP_Arming::update() (1 Hz) reports the failing checks as "PreArm: <reason>" every 30 s,
//    and 4 s after the last report when the checks went from passing to failing.
//  - Nothing disarms by itself: not the end of a mission, not HOLD. Disarming outside AUTO resets the
//    mission, so AUTO starts again from its first item.
#include "services/autopilot/mavlink/enums.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

namespace {

constexpr Duration kPrearmDisplay = seconds(30);           // PREARM_DISPLAY_PERIOD
constexpr Duration kPrearmReportImmediately = seconds(4);  // report_immediately's pause

bool requires_position(RoverMode m) {
    return m == RoverMode::Auto || m == RoverMode::Guided || m == RoverMode::Rtl ||
           m == RoverMode::SmartRtl || m == RoverMode::Loiter;
}

bool allows_arming(RoverMode m) {
    return m != RoverMode::Rtl && m != RoverMode::SmartRtl && m != RoverMode::Initialising;
}

}  // namespace

bool RoverSim::is_armed() const {
    if (!config_.firmware.arming_checks) {
        return armed_;
    }
    return armed_ || params_.get("ARMING_REQUIRE", 1) == 0;
}

std::vector<std::string> RoverSim::failing_checks() const {
    std::vector<std::string> reasons;
    if (params_.get("ARMING_CHECK", 1) == 0) {
        return reasons;
    }
    if (!failing_check_.empty()) {
        reasons.push_back(failing_check_);
    }
    if (!gps_fix_ && requires_position(mode_)) {
        reasons.emplace_back("Need Position Estimate");  // AP_Arming_Rover::gps_checks()
    }
    return reasons;
}

std::uint8_t RoverSim::arm(bool on, bool force, TimePoint now) {
    handle_timeout(now);
    const std::uint8_t result = arm_disarm(on, force);
    out_.release(now);
    return result;
}

std::uint8_t RoverSim::arm_disarm(bool on, bool force) {
    if (!on) {
        if (is_armed() && armed_) {
            armed_ = false;
            text(mavlink::kSeverityInfo, "Throttle disarmed");
            if (mode_ != RoverMode::Auto) {
                mission_running_ = false;  // AP_Mission::reset(): AUTO starts from the first item
                mission_complete_ = false;
                current_seq_ = 0;
            }
        }
        return mavlink::kResultAccepted;
    }
    if (is_armed()) {
        return mavlink::kResultAccepted;
    }
    if (!force) {
        auto reasons = failing_checks();
        if (!allows_arming(mode_)) {
            reasons.emplace_back("Mode not armable");  // AP_Arming_Rover::arm_checks()
        }
        if (!reasons.empty()) {
            for (const auto& r : reasons) {
                text(mavlink::kSeverityCritical, "Arm: " + r);
            }
            ++counters_.arm_refused;
            return mavlink::kResultFailed;
        }
    }
    armed_ = true;
    planned_speed_ = 0;  // the waypoint controller starts from rest
    text(mavlink::kSeverityInfo, "Throttle armed");
    if (!force && params_.get("ARMING_CHECK", 1) == 0) {
        text(mavlink::kSeverityWarning, "Warning: Arming Checks Disabled");
    }
    return mavlink::kResultAccepted;
}

void RoverSim::set_gps_fix(bool fix, TimePoint now) {
    handle_timeout(now);
    gps_fix_ = fix;
}

void RoverSim::fail_check(std::string reason, TimePoint now) {
    handle_timeout(now);
    failing_check_ = std::move(reason);
}

void RoverSim::arming_update(TimePoint now) {
    if (!config_.firmware.arming_checks || phase_ != BootPhase::Ready) {
        return;
    }
    // last_prearm_display_ starts at the boot (AP: 0 ms), and the checks count as failing then, so a check
    // failing from the start is first reported 30 s after the boot.
    bool display = false;
    const Duration since = now - last_prearm_display_;
    if ((report_immediately_ && since > kPrearmReportImmediately) || since > kPrearmDisplay) {
        report_immediately_ = false;
        display = true;
        last_prearm_display_ = now;
    }
    if (is_armed()) {
        prearm_failing_ = false;  // pre_arm_checks() passes at once when armed
        return;
    }
    const auto reasons = failing_checks();
    const bool failing = !reasons.empty();
    if (failing && !prearm_failing_) {
        report_immediately_ = true;
    }
    prearm_failing_ = failing;
    if (display) {
        for (const auto& r : reasons) {
            text(mavlink::kSeverityCritical, "PreArm: " + r);
        }
    }
}

}  // namespace airseg::apmsim
