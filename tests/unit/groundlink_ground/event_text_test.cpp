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

TEST(EventText, AModeChangeNobodyCanSeeIsNoEvent) {
    const ModeChanged same{VehicleState::Manual, VehicleState::Manual, "MANUAL", "MANUAL",
                           ModeChangeCause::External};
    EXPECT_FALSE(mode_change_event(same));
    const ModeChanged state_only{VehicleState::ConfigureCheck, VehicleState::Directed, "MANUAL", "MANUAL",
                                 ModeChangeCause::Requested};
    ASSERT_TRUE(mode_change_event(state_only));
    EXPECT_EQ(*mode_change_event(state_only),
              "vehicle STARTING -> DIRECTED (autopilot mode MANUAL -> MANUAL)");
}

// While a plan drives, the board's mission is the plan's rolling window: its slots and its texts about them
// say nothing to an operator; the plan's own event says which waypoint, once.
TEST(EventText, WhileAPlanDrivesWaypointsAreNamedInPlanTermsOnce) {
    using flightplan::PlanProgress;
    using flightplan::PlanState;
    EXPECT_TRUE(plan_drives_mission(PlanState::Running));
    EXPECT_TRUE(plan_drives_mission(PlanState::Paused));
    EXPECT_FALSE(plan_drives_mission(PlanState::None));
    EXPECT_FALSE(plan_drives_mission(PlanState::Done));
    EXPECT_TRUE(is_window_text("Reached waypoint #3 dist 1m"));
    EXPECT_TRUE(is_window_text("flight plan received"));
    EXPECT_TRUE(is_window_text("Flight plan received"));
    EXPECT_TRUE(is_window_text("Mission: 4 WP"));
    EXPECT_FALSE(is_window_text("PreArm: Compass not calibrated"));
    EXPECT_FALSE(is_window_text("Mission complete, changing mode to HOLD"));

    const PlanProgress before{PlanState::Running, 0, 7, 6};
    EXPECT_EQ(plan_reached_text(before, {PlanState::Running, 0, 8, 7}), "plan waypoint 7 reached");
    EXPECT_EQ(plan_reached_text(before, {PlanState::Running, 1, 12, 9}),
              "plan waypoints reached: 3 more, next 12");
    EXPECT_FALSE(plan_reached_text(before, before)) << "no change, no event";
    EXPECT_FALSE(plan_reached_text(before, {PlanState::Running, 0, 0, 0})) << "a new plan starts again";
}

// A plan that takes over (loaded, over a running one too, or resumed after a restart) is announced once; the
// same plan paused and resumed, or one that ended, is not. A plan appended to the announced one is announced
// as an extension, once per append.
TEST(EventText, APlanThatTakesOverIsAnnouncedOnceAndAnAppendAsAnExtension) {
    using flightplan::PlanProgress;
    using flightplan::PlanState;
    const PlanProgress first{PlanState::Running, 0, 0, 0, 3, "north field"};
    EXPECT_EQ(plan_announcement_text(std::nullopt, first), "plan 'north field' started");
    EXPECT_FALSE(plan_announcement_text(AnnouncedPlan{3, 0}, first)) << "announced already";
    auto paused = first;
    paused.state = PlanState::Paused;
    EXPECT_FALSE(plan_announcement_text(AnnouncedPlan{3, 0}, paused)) << "the same plan paused";
    const PlanProgress second{PlanState::Running, 0, 0, 0, 4, "south"};
    EXPECT_EQ(plan_announcement_text(AnnouncedPlan{3, 0}, second), "plan 'south' started")
        << "over the running one";
    const PlanProgress waiting{PlanState::Paused, 0, 0, 0, 5, "later"};
    EXPECT_EQ(plan_announcement_text(AnnouncedPlan{4, 0}, waiting), "plan 'later' loaded, paused");
    const PlanProgress cleared{PlanState::None, 0, 0, 0, 6, ""};
    EXPECT_FALSE(plan_announcement_text(AnnouncedPlan{5, 0}, cleared)) << "no plan drives";
    auto done = second;
    done.state = PlanState::Done;
    EXPECT_FALSE(plan_announcement_text(AnnouncedPlan{3, 0}, done));

    auto appended = first;
    appended.extensions = 1;
    EXPECT_EQ(plan_announcement_text(AnnouncedPlan{3, 0}, appended), "plan 'north field' extended");
    EXPECT_FALSE(plan_announcement_text(AnnouncedPlan{3, 1}, appended)) << "that append was announced";
    appended.extensions = 2;
    appended.state = PlanState::Paused;
    EXPECT_EQ(plan_announcement_text(AnnouncedPlan{3, 1}, appended), "plan 'north field' extended")
        << "an append to the paused plan";
    auto other = appended;
    other.generation = 4;
    other.state = PlanState::Running;
    EXPECT_EQ(plan_announcement_text(AnnouncedPlan{3, 2}, other), "plan 'north field' started")
        << "another plan of the same name, loaded after appends";
}

}  // namespace
}  // namespace airseg::groundlink
