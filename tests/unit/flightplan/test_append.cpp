// Appending a plan to a running one: the merged text expands like the running plan up to its end, and the
// feeder continues on it without disturbing the autopilot, mid-route and after the plan was done.
#include <gtest/gtest.h>

#include <numeric>
#include <sstream>

#include "services/flightplan/expander.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "services/flightplan/plan_merge.hpp"
#include "tests/unit/flightplan/plan_text.hpp"
#include "tests/unit/flightplan/sim_autopilot.hpp"

namespace airseg::flightplan {
namespace {

std::string line_plan(const std::string& name, double lat, int count, const std::string& extra = "") {
    std::ostringstream o;
    o.precision(9);
    o << "plan:\n  name: " << name << "\n" << extra << "  elements:\n";
    for (int i = 0; i < count; ++i)
        o << "    - waypoint: {lat: " << lat + i * 1e-4 << ", lon: 1.98}\n";
    return o.str();
}

using test::load;

std::vector<LatLon> expand(const std::shared_ptr<const Plan>& plan) {
    std::vector<LatLon> out;
    Expander e(plan);
    while (auto w = e.next())
        out.push_back(w->position);
    return out;
}

TEST(FlightplanAppend, MergedPlanKeepsTheRunningPlanAndAddsElementsBlocksAndZones) {
    const std::string a = line_plan("a", 41.0, 3,
                                    "  blocks:\n    - name: lost\n      elements:\n"
                                    "        - waypoint: {lat: 40.99, lon: 1.98}\n");
    const std::string b = line_plan("b", 41.001, 2,
                                    "  no_fly:\n    - name: shed\n      polygon: [[41.1, 1.9], [41.1, 1.91], "
                                    "[41.11, 1.91]]\n");
    auto merged = append_plan_text(a, b);
    ASSERT_TRUE(merged.text) << merged.error;
    auto plan = load(*merged.text);
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->name, "a");
    EXPECT_EQ(plan->no_fly.size(), 1u);
    EXPECT_NE(plan->find("lost"), kNoNode);
    auto got = expand(plan);
    auto want = expand(load(a));
    const auto tail = expand(load(b));
    want.insert(want.end(), tail.begin(), tail.end());
    EXPECT_EQ(got, want);
}

TEST(FlightplanAppend, BrokenTextIsReportedNotThrown) {
    EXPECT_FALSE(append_plan_text("plan: [", "plan: {}").text);
    EXPECT_FALSE(append_plan_text("plan:\n  name: a\n", "- 1\n").text);
}

TEST(FlightplanAppend, FeederContinuesMidRouteAndAfterTheEndWithoutStopping) {
    test::Harness h;
    const std::string a = line_plan("a", 41.0, 12);
    auto stream = std::make_unique<Expander>(load(a));
    Expander* running = stream.get();
    h.feeder.replace_plan(PlanFeed{std::move(stream), "a"}, h.now);
    for (int i = 0; i < 5; ++i)
        h.step();
    ASSERT_GT(h.reached.size(), 0u);
    const auto writes_before = h.ap.writes();

    auto merged = append_plan_text(a, line_plan("b", 41.002, 6));
    ASSERT_TRUE(merged.text);
    auto plan_ab = load(*merged.text);
    auto next = std::make_unique<Expander>(plan_ab);
    ASSERT_TRUE(next->restore(running->origin(), running->position()));
    running = next.get();
    h.feeder.continue_with(PlanFeed{std::move(next), "a"}, h.now);
    EXPECT_EQ(h.ap.writes(), writes_before) << "the window on the autopilot was already right";
    ASSERT_LT(h.run_until_done(200), 200);
    for (int i = 0; i < 3; ++i)
        h.step();
    EXPECT_EQ(h.ap.visited(), expand(plan_ab));
    EXPECT_TRUE(h.ap.parked());

    // After the end: the appended waypoints follow from where the vehicle is parked.
    auto merged2 = append_plan_text(*merged.text, line_plan("c", 41.003, 4));
    ASSERT_TRUE(merged2.text);
    auto plan_abc = load(*merged2.text);
    auto third = std::make_unique<Expander>(plan_abc);
    ASSERT_TRUE(third->restore(running->origin(), running->position()));
    h.feeder.continue_with(PlanFeed{std::move(third), "a"}, h.now);
    EXPECT_EQ(h.feeder.progress().state, PlanState::Running);
    ASSERT_LT(h.run_until_done(200), 200);
    for (int i = 0; i < 3; ++i)
        h.step();
    EXPECT_EQ(h.ap.visited(), expand(plan_abc));
    std::vector<std::uint64_t> all(22);
    std::iota(all.begin(), all.end(), 0);
    EXPECT_EQ(h.reached, all);
    EXPECT_EQ(h.feeder.progress().waypoints_reached, 22u);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
    EXPECT_EQ(h.feeder.progress().starvation_holds, 0u);
}

}  // namespace
}  // namespace airseg::flightplan
