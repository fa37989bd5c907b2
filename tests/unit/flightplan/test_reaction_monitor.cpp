// ReactionMonitor in simulated time: link loss after T without a break, battery with hysteresis, geofence
// exits, and triggers built from a loaded plan.
#include <gtest/gtest.h>

#include "services/flightplan/plan_loader.hpp"
#include "services/flightplan/reaction_monitor.hpp"
#include "tests/support/tree_paths.hpp"

namespace airseg::flightplan {
namespace {

ReactionSettings link_only(Duration after) {
    ReactionSettings s;
    s.link_loss = Reaction{ReactionAction::GotoBlock, "lost-link", 0};
    s.link_loss_after = after;
    return s;
}

TEST(FlightplanReactions, LinkLossFiresOnceAfterTheDelayAndRecovers) {
    ReactionMonitor m(link_only(seconds(30)));
    const TimePoint t0{};
    m.on_link(false, t0);
    EXPECT_EQ(m.poll_timeout(), t0 + seconds(30));
    m.handle_timeout(t0 + seconds(29));
    EXPECT_FALSE(m.poll_trigger().has_value());
    m.handle_timeout(t0 + seconds(30));
    auto t = m.poll_trigger();
    ASSERT_TRUE(t.has_value());
    EXPECT_EQ(t->cause, ReactionTrigger::Cause::LinkLoss);
    EXPECT_EQ(t->reaction.action, ReactionAction::GotoBlock);
    EXPECT_EQ(t->reaction.target, "lost-link");
    EXPECT_EQ(t->at, t0 + seconds(30));
    m.on_link(false, t0 + seconds(40));  // still down: no second trigger
    m.handle_timeout(t0 + seconds(100));
    EXPECT_FALSE(m.poll_trigger().has_value());
    EXPECT_EQ(m.poll_timeout(), kNever);
    m.on_link(true, t0 + seconds(101));
    t = m.poll_trigger();
    ASSERT_TRUE(t.has_value());
    EXPECT_EQ(t->cause, ReactionTrigger::Cause::LinkRecovered);
    EXPECT_FALSE(m.link_loss_active());
}

TEST(FlightplanReactions, ShortLinkDropoutsDoNotFire) {
    ReactionMonitor m(link_only(seconds(10)));
    TimePoint t{};
    for (int i = 0; i < 20; ++i) {
        m.on_link(false, t);
        t += seconds(9);
        m.handle_timeout(t);
        m.on_link(true, t);
        t += seconds(1);
    }
    EXPECT_FALSE(m.poll_trigger().has_value());
}

TEST(FlightplanReactions, LowBatteryFiresOnceWithHysteresis) {
    ReactionSettings s;
    s.low_battery = Reaction{ReactionAction::ReturnHome, "", 0};
    s.low_battery_percent = 20.0;
    ReactionMonitor m(s);
    const TimePoint t{};
    int fired = 0;
    for (double pct : {40.0, 25.0, 19.5, 18.0, 22.0, 24.9, 19.0, 26.0, 19.0, -3.0, 150.0}) {
        m.on_battery(pct, t);
        while (auto trig = m.poll_trigger()) {
            EXPECT_EQ(trig->cause, ReactionTrigger::Cause::LowBattery);
            EXPECT_EQ(trig->reaction.action, ReactionAction::ReturnHome);
            ++fired;
        }
    }
    EXPECT_EQ(fired, 2);  // at 19.5, and again at 19.0 after re-arming at 26
    EXPECT_EQ(m.rejected_samples(), 2u);
}

TEST(FlightplanReactions, GeofenceFromALoadedPlan) {
    const auto r = load_plan_file(::airseg::test::source_dir() + "/config/plans/rover-survey.yaml");
    ASSERT_TRUE(r.ok()) << to_string(r.errors);
    ReactionMonitor m(ReactionSettings::from_plan(*r.plan));
    const TimePoint t{};
    m.on_position({41.2760, 1.9880}, t);  // inside
    EXPECT_FALSE(m.poll_trigger().has_value());
    m.on_position({41.2800, 1.9880}, t);  // north of the fence
    auto trig = m.poll_trigger();
    ASSERT_TRUE(trig.has_value());
    EXPECT_EQ(trig->cause, ReactionTrigger::Cause::Geofence);
    EXPECT_EQ(trig->reaction.action, ReactionAction::Hold);
    m.on_position({41.2801, 1.9880}, t);
    EXPECT_FALSE(m.poll_trigger().has_value());
    m.on_position({41.2760, 1.9880}, t);  // back inside, well clear of the edge: re-armed
    m.on_position({41.2800, 1.9880}, t);
    EXPECT_TRUE(m.poll_trigger().has_value());
    // The plan's link-loss reaction is the lost-link block after 30 s.
    m.on_link(false, t);
    EXPECT_EQ(m.poll_timeout(), t + seconds(30));
}

}  // namespace
}  // namespace airseg::flightplan
