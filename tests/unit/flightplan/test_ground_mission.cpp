// A ground station's mission as a flight plan: the text the loader takes, and when it may replace the plan.
#include "services/flightplan/ground_mission.hpp"

#include <gtest/gtest.h>

#include "services/flightplan/plan_loader.hpp"

namespace airseg::flightplan {
namespace {

using autopilot::MissionItem;

TEST(GroundMission, WaypointsAndHoldsBecomeAPlanTheLoaderTakes) {
    MissionItem wp;
    wp.lat = 41.2753001;
    wp.lon = 1.9870002;
    MissionItem timed;
    timed.lat = 41.2760;
    timed.lon = 1.9875;
    timed.hold_s = 20;
    MissionItem stop;
    stop.kind = MissionItem::Kind::Stop;
    stop.lat = 41.2765;
    stop.lon = 1.9880;
    const auto text = ground_mission_plan({wp, timed, stop});
    const auto loaded = load_plan_text(text, kGroundMissionSource);
    ASSERT_TRUE(loaded.ok()) << text << (loaded.errors.empty() ? "" : loaded.errors[0].message);
    const Plan& plan = *loaded.plan;
    EXPECT_EQ(plan.name, kGroundMissionName);
    const auto& elements = plan.children(plan.main_list);
    ASSERT_EQ(elements.size(), 3u);
    EXPECT_EQ(plan.nodes[elements[0]].kind, NodeKind::Waypoint);
    EXPECT_NEAR(plan.nodes[elements[0]].geo.lat, 41.2753001, 1e-9);
    EXPECT_NEAR(plan.nodes[elements[0]].geo.lon, 1.9870002, 1e-9);
    EXPECT_EQ(plan.nodes[elements[1]].kind, NodeKind::Hold);
    EXPECT_EQ(plan.extra(elements[1]).hold_seconds, 20.0);
    EXPECT_EQ(plan.nodes[elements[2]].kind, NodeKind::Hold);
    EXPECT_FALSE(plan.extra(elements[2]).hold_seconds);
}

TEST(GroundMission, OnlyARunningOrPausedPlanRefusesIt) {
    FeederProgress p;
    for (auto state : {PlanState::None, PlanState::Done, PlanState::Interrupted, PlanState::Failed}) {
        p.state = state;
        EXPECT_FALSE(ground_mission_refusal(p)) << to_string(state);
    }
    p.plan_name = "survey";
    for (auto state : {PlanState::Running, PlanState::Paused}) {
        p.state = state;
        const auto why = ground_mission_refusal(p);
        ASSERT_TRUE(why) << to_string(state);
        EXPECT_NE(why->find("a flight plan is running (survey); pause is not enough"), std::string::npos);
        EXPECT_NE(why->find("airsegctl plan load"), std::string::npos);
    }
}

}  // namespace
}  // namespace airseg::flightplan
