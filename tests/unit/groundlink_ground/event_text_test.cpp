// The events an operator reads in airsegctl watch and log: operator words, and a routine boot notice is
// not shown as an error.
#include <gtest/gtest.h>

#include "services/groundlink/event_text.hpp"

namespace airseg::groundlink {
namespace {

using autopilot::ModeChangeCause;
using autopilot::ModeChanged;
using autopilot::VehicleState;
using Sev = protocol::Event::Severity;

TEST(EventText, AModeChangeWithinAStateNamesTheModesOnly) {
    const ModeChanged m{VehicleState::ConfigureCheck, VehicleState::ConfigureCheck, "INITIALISING", "MANUAL",
                        ModeChangeCause::External};
    const auto text = mode_change_text(m);
    EXPECT_EQ(text.find("configure_check"), std::string::npos) << text;
    EXPECT_EQ(text.rfind("autopilot mode INITIALISING -> MANUAL", 0), 0u) << text;
}

TEST(EventText, AStateChangeUsesTheOperatorsStateNames) {
    const ModeChanged m{VehicleState::ConfigureCheck, VehicleState::Parking, "MANUAL", "HOLD",
                        ModeChangeCause::Requested};
    EXPECT_EQ(mode_change_text(m), "vehicle STARTING -> PARKING (autopilot mode MANUAL -> HOLD)");
    const ModeChanged rc{VehicleState::WaypointNavigation, VehicleState::Manual, "AUTO", "MANUAL",
                         ModeChangeCause::External};
    EXPECT_NE(mode_change_text(rc).find("WAYPOINT_NAVIGATION -> MANUAL"), std::string::npos);
    EXPECT_NE(mode_change_text(rc).find("not asked for by airsegd"), std::string::npos);
}

TEST(EventText, BootCalibrationNoticesAreInfoAndRealFailuresStayErrors) {
    // ArduPilot sends these at MAV_SEVERITY_CRITICAL (2) or ALERT (1) on every power-up.
    EXPECT_EQ(status_text_severity(2, "Beginning INS calibration; do not move vehicle"), Sev::Info);
    EXPECT_EQ(status_text_severity(1, "Initialising APM..."), Sev::Info);
    EXPECT_EQ(status_text_severity(2, "Warming up ADC..."), Sev::Info);
    EXPECT_EQ(status_text_severity(2, "Calibration FAILED"), Sev::Error);
    EXPECT_EQ(status_text_severity(2, "PreArm: Compass not calibrated"), Sev::Error);
    EXPECT_EQ(status_text_severity(3, "EKF variance"), Sev::Error);
    EXPECT_EQ(status_text_severity(4, "Low battery"), Sev::Warning);
    EXPECT_EQ(status_text_severity(6, "Ready to drive."), Sev::Info);
}

}  // namespace
}  // namespace airseg::groundlink
