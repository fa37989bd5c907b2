// Where the plan is, said in airsegctl watch and log as the map says it (groundside/event_wording.hpp):
// "running — waypoint 6 of 14 — scan 'field' — 140 m left (about 93 s)", from plan.show's and plan.geometry's
// answers (the fixture plan of the map's browser test) and a telemetry sample.
#include <gtest/gtest.h>

#include "groundside/event_wording.hpp"
#include "groundside/watch_view.hpp"

namespace airseg::groundside {
namespace {

namespace proto = groundlink::protocol;
using Json = nlohmann::json;

/// plan.show's answer for the map fixture's plan (ground/map/fixture_main.cpp): 14 waypoints.
Json show_answer() {
    return Json::parse(R"({"state": "running", "name": "fixture", "elements": [
      {"path": "plan.elements[0]", "kind": "waypoint", "name": "start", "line": 3, "waypoints": 1},
      {"path": "plan.elements[1]", "kind": "waypoint", "name": null, "line": 5, "waypoints": 1},
      {"path": "plan.elements[2]", "kind": "scan", "name": "field", "line": 7, "waypoints": 6},
      {"path": "plan.elements[3]", "kind": "hold", "name": "wait", "line": 12, "waypoints": 1},
      {"path": "plan.elements[4]", "kind": "orbit", "name": null, "line": 14, "waypoints": 5}]})");
}

/// plan.geometry's answer for it: the scan's lines are its waypoints.
Json geometry_answer() {
    return Json::parse(R"({"name": "fixture", "truncated": false, "elements": [
      {"path": "plan.elements[0]", "kind": "waypoint", "closed": false, "points": [[41.2752, 1.9868]]},
      {"path": "plan.elements[1]", "kind": "waypoint", "closed": false, "points": [[41.2757, 1.9868]]},
      {"path": "plan.elements[2]", "kind": "scan", "closed": true,
       "points": [[41.2757, 1.9870], [41.2763, 1.9870], [41.2763, 1.9882], [41.2757, 1.9882]],
       "lines": [[41.2757, 1.9871], [41.2763, 1.9871], [41.2763, 1.9878], [41.2757, 1.9878],
                 [41.2757, 1.9881], [41.2763, 1.9881]]},
      {"path": "plan.elements[3]", "kind": "hold", "closed": false, "points": [[41.2760, 1.9875]]},
      {"path": "plan.elements[4]", "kind": "orbit", "closed": false,
       "points": [[41.2761, 1.9887], [41.2760, 1.9888], [41.2759, 1.9887], [41.2760, 1.9886], [41.2761, 1.9887]]}],
      "no_fly": []})");
}

/// Mid-scan, as the map's "mid-scan" picture: on the scan's second line, heading for waypoint 6 (index 5).
proto::Telemetry mid_scan() {
    proto::Telemetry t;
    t.plan_state = 1;
    t.next_waypoint = 5;
    t.plan_element = 2;
    t.lat_deg = 41.27615;
    t.lon_deg = 1.9878;
    t.ground_speed_mps = 1.5;
    t.gps_fix = 3;
    return t;
}

TEST(EventWording, PlanFactsComeFromPlanShowAndPlanGeometry) {
    const auto facts = plan_facts(show_answer(), geometry_answer());
    ASSERT_EQ(facts.waypoints, 14u);
    ASSERT_EQ(facts.top.size(), 5u);
    EXPECT_EQ(facts.top[2].kind, "scan");
    EXPECT_EQ(facts.top[2].name, "field");
    EXPECT_EQ(facts.top[1].name, "") << "a null name is no name";
    ASSERT_EQ(facts.route.size(), 14u) << "the points of the main list's elements, a scan's lines";
    EXPECT_EQ(facts.route[2], std::make_pair(41.2757, 1.9871));
    EXPECT_EQ(facts.route[13], std::make_pair(41.2761, 1.9887));

    auto endless = show_answer();
    endless["elements"][4]["waypoints"] = nullptr;  // an endless repeat
    EXPECT_FALSE(plan_facts(endless, geometry_answer()).waypoints);
    EXPECT_TRUE(plan_facts(endless, geometry_answer()).route.empty());
    EXPECT_EQ(plan_facts(endless).top.size(), 5u) << "the names are known all the same";

    auto truncated = geometry_answer();
    truncated["truncated"] = true;
    EXPECT_TRUE(plan_facts(show_answer(), truncated).route.empty()) << "no number is better than a wrong one";
    auto other = geometry_answer();
    other["elements"][4]["points"].erase(0);  // 13 points for 14 waypoints: not the same plan
    EXPECT_TRUE(plan_facts(show_answer(), other).route.empty());
    auto bad = geometry_answer();
    bad["elements"][0]["points"][0] = "x";
    EXPECT_TRUE(plan_facts(show_answer(), bad).route.empty());

    EXPECT_FALSE(plan_facts(Json()).waypoints) << "no plan.show answer: nothing known";
    EXPECT_FALSE(plan_facts(Json::parse(R"({"state": "none"})")).waypoints);
    EXPECT_TRUE(plan_facts(Json::parse(R"({"elements": [1, 2]})")).top.empty());
}

TEST(EventWording, ProgressIsSaidAsTheMapSaysIt) {
    const auto facts = plan_facts(show_answer(), geometry_answer());
    const auto t = mid_scan();
    // The distance left as the map measures it (Leaflet's sphere): 50 m to waypoint 6, then along the rest
    // of the plan to the orbit's end, 359 m in all; at 1.5 m/s, 239 s.
    EXPECT_EQ(progress_words(t, facts),
              "running — waypoint 6 of 14 — scan 'field' — 359 m left (about 4 min)");
    auto fast = t;
    fast.ground_speed_mps = 5;
    EXPECT_EQ(progress_words(fast, facts),
              "running — waypoint 6 of 14 — scan 'field' — 359 m left (about 72 s)");

    auto slow = t;
    slow.ground_speed_mps = 0.2;  // standing: no time said
    EXPECT_EQ(progress_words(slow, facts), "running — waypoint 6 of 14 — scan 'field' — 359 m left");
    auto unnamed = t;
    unnamed.plan_element = 1;
    unnamed.next_waypoint = 1;
    unnamed.lat_deg = 41.2752;
    unnamed.lon_deg = 1.9868;
    EXPECT_TRUE(progress_words(unnamed, facts)
                    .starts_with("running — waypoint 2 of 14 — waypoint plan.elements[1] — "))
        << progress_words(unnamed, facts);
    auto far = t;
    far.lat_deg = 41.29;  // 1.6 km north
    EXPECT_TRUE(progress_words(far, facts).ends_with(" — 1.9 km left (about 21 min)"))
        << progress_words(far, facts);

    // What is not known is left out, never guessed.
    EXPECT_EQ(progress_words(t, PlanFacts{}), "running — waypoint 6");
    EXPECT_EQ(progress_words(t, plan_facts(show_answer())), "running — waypoint 6 of 14 — scan 'field'");
    auto lost = t;
    lost.no_position = true;
    EXPECT_EQ(progress_words(lost, facts), "running — waypoint 6 of 14 — scan 'field'")
        << "no place, no distance";
    auto past = t;
    past.next_waypoint = 14;
    past.plan_element = 9;
    EXPECT_EQ(progress_words(past, facts), "running — waypoint 15")
        << "an index past the count is not 'of N'";

    auto paused = t;
    paused.plan_state = 2;
    EXPECT_TRUE(progress_words(paused, facts).starts_with("paused — waypoint 6 of 14"))
        << progress_words(paused, facts);
    auto done = t;
    done.plan_state = 3;
    EXPECT_EQ(progress_words(done, facts), "done");
    EXPECT_EQ(progress_words(proto::Telemetry{}, facts), "no plan running");

    EXPECT_EQ(distance_words(140.4), "140 m");
    EXPECT_EQ(distance_words(999.4), "999 m");
    EXPECT_EQ(distance_words(2140), "2.1 km");
}

TEST(WatchView, SaysThePlansProgressAndItsEventsOfN) {
    WatchState w;
    const auto t0 = WatchState::Clock::now();
    w.take(mid_scan(), t0);
    w.take(proto::Event{proto::Event::Severity::Info, "plan waypoint 4 reached"}, t0);
    auto screen = w.render(t0);
    EXPECT_NE(screen.find("progress    running — waypoint 6\n"), std::string::npos)
        << "the plan's facts not known yet: no count\n"
        << screen;
    EXPECT_NE(screen.find("info: waypoint 5 reached\n"), std::string::npos) << screen;

    w.set_plan(plan_facts(show_answer(), geometry_answer()));
    w.take(proto::Event{proto::Event::Severity::Info, "plan waypoint 5 reached"}, t0);
    screen = w.render(t0);
    EXPECT_NE(
        screen.find("progress    running — waypoint 6 of 14 — scan 'field' — 359 m left (about 4 min)\n"),
        std::string::npos)
        << screen;
    EXPECT_NE(screen.find("plan        running  element 2  next waypoint 6 (index 5)\n"), std::string::npos)
        << "the index plan.skip takes\n"
        << screen;
    EXPECT_NE(screen.find("info: waypoint 6 of 14 reached\n"), std::string::npos) << screen;
    const auto j = w.to_json(t0);
    EXPECT_EQ(j["vehicle"]["plan"]["progress"],
              "running — waypoint 6 of 14 — scan 'field' — 359 m left (about 4 min)");
    EXPECT_EQ(j["vehicle"]["plan"]["waypoints"], 14);
    EXPECT_EQ(j["events"].back(), "info: waypoint 6 of 14 reached");

    auto none = mid_scan();
    none.plan_state = 0;
    w.take(none, t0);
    EXPECT_EQ(w.render(t0).find("progress    "), std::string::npos) << "no plan line without a plan";
    EXPECT_FALSE(w.to_json(t0)["vehicle"].contains("plan"));
}

/// A watch of the mid-scan sample with the plan's facts, told that plan waypoint 5 (the sixth) was reached.
WatchState watching_the_scan_at_its_sixth_waypoint(WatchState::Clock::time_point t0) {
    WatchState w;
    w.take(mid_scan(), t0);
    w.set_plan(plan_facts(show_answer(), geometry_answer()));
    w.take(proto::Event{proto::Event::Severity::Info, "plan waypoint 5 reached"}, t0);
    return w;
}

// Another plan over the running one leaves the state "running": only the vehicle's announcement says the
// facts held are the last plan's.
TEST(WatchView, AnotherPlansAnnouncementForgetsTheLastPlansFacts) {
    EXPECT_TRUE(announces_plan("plan 'north field' started"));
    EXPECT_TRUE(announces_plan("plan 'x' loaded, paused"));
    EXPECT_FALSE(announces_plan("plan waypoint 4 reached"));
    EXPECT_FALSE(announces_plan("plan 'x' done"));
    EXPECT_FALSE(announces_plan("autopilot: plan 'x' started by a text"));
    EXPECT_TRUE(announces_plan("plan 'north field' extended"));
    EXPECT_TRUE(extends_plan("plan 'north field' extended"));
    EXPECT_FALSE(extends_plan("plan 'north field' started"));
    EXPECT_FALSE(extends_plan("autopilot: plan 'x' extended by a text"));

    const auto t0 = WatchState::Clock::now();
    WatchState w = watching_the_scan_at_its_sixth_waypoint(t0);
    ASSERT_EQ(w.plan().waypoints, 14u);
    w.take(proto::Event{proto::Event::Severity::Info, "plan 'second' started"}, t0);
    EXPECT_FALSE(w.plan().waypoints) << "the count was the last plan's";
    EXPECT_TRUE(w.plan().top.empty());
    w.take(proto::Event{proto::Event::Severity::Info, "plan waypoint 5 reached"}, t0);
    const auto screen = w.render(t0);
    EXPECT_NE(screen.find("info: plan 'second' started\n"), std::string::npos) << screen;
    EXPECT_NE(screen.find("progress    running — waypoint 6\n"), std::string::npos) << "no count: " << screen;
    EXPECT_NE(screen.rfind("info: waypoint 6 reached\n"), std::string::npos)
        << "the same index in the new plan is a new happening, without the old count\n"
        << screen;
}

// A plan appended to the running one: the count grew, so it is forgotten until asked again; the plan goes on,
// so a waypoint reached before the append and told again is still the same happening.
TEST(WatchView, AnAppendsAnnouncementForgetsTheCountButNotTheWaypointsReached) {
    const auto t0 = WatchState::Clock::now();
    WatchState w = watching_the_scan_at_its_sixth_waypoint(t0);
    ASSERT_EQ(w.plan().waypoints, 14u);
    w.take(proto::Event{proto::Event::Severity::Info, "plan 'field' extended"}, t0);
    EXPECT_FALSE(w.plan().waypoints) << "the count was the plan's before the append";
    w.take(proto::Event{proto::Event::Severity::Info, "plan waypoint 5 reached"}, t0);
    const auto screen = w.render(t0);
    EXPECT_NE(screen.find("info: plan 'field' extended\n"), std::string::npos) << screen;
    EXPECT_EQ(screen.find("info: waypoint 6 reached\n"), std::string::npos)
        << "told again, not a new happening: " << screen;
    EXPECT_NE(screen.find("progress    running — waypoint 6\n"), std::string::npos) << "no count: " << screen;
}

}  // namespace
}  // namespace airseg::groundside
