// The lazy expander: scan geometry (spacing, order, coverage), orbit, repeat/goto/speed semantics, seek and
// restore equal to a full expansion, and the on-the-fly no-fly check.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "services/flightplan/expander.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "tests/unit/flightplan/plan_text.hpp"

namespace airseg::flightplan {
namespace {

using test::load;

std::vector<Waypoint> expand_all(std::shared_ptr<const Plan> plan, std::size_t limit = 10'000'000) {
    Expander e(std::move(plan));
    std::vector<Waypoint> out;
    while (out.size() < limit) {
        auto w = e.next();
        if (!w) {
            break;
        }
        out.push_back(*w);
    }
    return out;
}

const std::string kScanPlan = R"(plan:
  name: scan
  vehicle: {type: rover}
  elements:
    - scan:
        polygon: [[41.0, 2.0], [41.0, 2.002], [41.0012, 2.002], [41.0012, 2.0]]
        spacing: 8
        heading: 90
)";

TEST(FlightplanExpander, ScanLinesAreSpacedAlternateAndCoverThePolygon) {
    auto plan = load(kScanPlan);
    ASSERT_TRUE(plan);
    const auto wps = expand_all(plan);
    const std::uint32_t scan_id = plan->children(plan->main_list)[0];
    const NodeExtra& scan = plan->extra(scan_id);
    ASSERT_EQ(wps.size(), plan->count(scan_id));
    ASSERT_EQ(wps.size() % 2, 0u);
    // Lines run east-west: both ends of a line share the northing; consecutive lines are 8 m apart and
    // alternate direction.
    for (std::size_t i = 0; i + 1 < wps.size(); i += 2) {
        EXPECT_NEAR(wps[i].local.n, wps[i + 1].local.n, 1e-6);
        const bool eastward = wps[i + 1].local.e > wps[i].local.e;
        EXPECT_EQ(eastward, (i / 2) % 2 == 0) << "line " << i / 2;
        if (i >= 2) {
            EXPECT_NEAR(std::abs(wps[i].local.n - wps[i - 2].local.n), 8.0, 1e-6);
        }
    }
    // Coverage: every point of the polygon is within spacing/2 of the path.
    const auto& poly = scan.scan->polygon();
    double min_e = 1e9, max_e = -1e9, min_n = 1e9, max_n = -1e9;
    for (auto p : poly) {
        min_e = std::min(min_e, p.e), max_e = std::max(max_e, p.e);
        min_n = std::min(min_n, p.n), max_n = std::max(max_n, p.n);
    }
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> ue(min_e, max_e), un(min_n, max_n);
    for (int k = 0; k < 2000; ++k) {
        const Enu p{ue(rng), un(rng)};
        double best = 1e9;
        for (std::size_t i = 0; i + 1 < wps.size(); ++i) {
            best = std::min(best, distance_point_segment(p, wps[i].local, wps[i + 1].local));
        }
        EXPECT_LE(best, 4.0 + 1e-6) << p.e << "," << p.n;
    }
    // All waypoints lie inside (or on) the polygon.
    for (const auto& w : wps) {
        EXPECT_TRUE(point_in_polygon(w.local, poly) || distance_to_boundary(w.local, poly) < 1e-6);
    }
    EXPECT_TRUE(wps.front().first_of_element);
    EXPECT_TRUE(wps.back().last_of_element);
    EXPECT_EQ(wps.front().index, 0u);
    EXPECT_EQ(wps.back().index, wps.size() - 1);
}

TEST(FlightplanExpander, ConcavePolygonIsCoveredAndStepAddsPoints) {
    // An L shape, lines along north (heading 0), a waypoint at most every 10 m.
    auto plan = load(R"(plan:
  name: l-shape
  elements:
    - scan:
        polygon: [[41.0, 2.0], [41.0, 2.0012], [41.0004, 2.0012], [41.0004, 2.0005], [41.001, 2.0005], [41.001, 2.0]]
        spacing: 6
        step: 10
)");
    ASSERT_TRUE(plan);
    const auto wps = expand_all(plan);
    const std::uint32_t scan_id = plan->children(plan->main_list)[0];
    const NodeExtra& scan = plan->extra(scan_id);
    const auto& poly = scan.scan->polygon();
    // Along a line (lines run north: same easting) waypoints are at most `step` apart.
    std::size_t along_line = 0;
    for (std::size_t i = 0; i + 1 < wps.size(); ++i) {
        if (std::abs(wps[i].local.e - wps[i + 1].local.e) > 1e-6) {
            continue;
        }
        ++along_line;
        EXPECT_LE(distance(wps[i].local, wps[i + 1].local), 10.0 + 1e-6);
    }
    EXPECT_GT(along_line, wps.size() / 2);
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> ue(-10, 110), un(-10, 120);
    int inside = 0;
    for (int k = 0; k < 3000; ++k) {
        const Enu p{ue(rng), un(rng)};
        if (!point_in_polygon(p, poly)) {
            continue;
        }
        ++inside;
        double best = 1e9;
        for (std::size_t i = 0; i + 1 < wps.size(); ++i) {
            best = std::min(best, distance_point_segment(p, wps[i].local, wps[i + 1].local));
        }
        EXPECT_LE(best, 3.0 + 1e-6);
    }
    EXPECT_GT(inside, 500);
}

const std::string kMixedPlan = R"(plan:
  name: mixed
  elements:
    - waypoint: {name: a, lat: 41.0, lon: 2.0}
    - speed: 3
    - repeat:
        name: loop
        count: 4
        elements:
          - waypoint: {lat: 41.0001, lon: 2.0}
          - speed: 1.5
          - orbit: {lat: 41.0005, lon: 2.0005, radius: 10, turns: 1}
          - waypoint: {lat: 41.0002, lon: 2.0, speed: 4}
    - hold: {seconds: 12}
    - scan: {rectangle: {sw: [41.001, 2.001], ne: [41.0016, 2.0016]}, spacing: 5, heading: 45}
    - repeat:
        count: 3
        elements:
          - waypoint: {name: r, lat: 41.0, lon: 2.0003}
          - repeat: {count: 2, elements: [{waypoint: {lat: 41.0, lon: 2.0004}}, {hold: {until_released: true}}]}
    - waypoint: {lat: 41.0, lon: 2.0}
  blocks:
    - name: home-run
      elements:
        - waypoint: {lat: 41.0, lon: 2.0001}
        - goto: r
)";

TEST(FlightplanExpander, RepeatSpeedHoldAndOrbitSemantics) {
    auto plan = load(kMixedPlan);
    ASSERT_TRUE(plan);
    const auto wps = expand_all(plan);
    const auto& root = plan->extra(plan->main_list);
    EXPECT_EQ(wps.size(), *root.count);
    // Speed: the autopilot's own at first (the plan states no cruise_speed: 0), 3 after the speed element,
    // 1.5 after the inner one, and a per-waypoint 4.
    EXPECT_FALSE(plan->vehicle.cruise_speed_given);
    EXPECT_DOUBLE_EQ(wps[0].speed, 0.0);
    EXPECT_DOUBLE_EQ(wps[1].speed, 3.0);
    EXPECT_TRUE(wps[1].speed_changed);
    EXPECT_DOUBLE_EQ(wps[2].speed, 1.5);
    EXPECT_TRUE(wps[2].speed_changed);
    EXPECT_FALSE(wps[3].speed_changed);
    const NodeExtra& orbit = plan->extra(plan->children(root.children[2])[2]);
    const std::uint64_t orbit_n = orbit.orbit->count();
    EXPECT_EQ(orbit_n, orbit.orbit->points_per_turn + 1);
    for (std::uint64_t k = 0; k < orbit_n; ++k) {
        EXPECT_NEAR(distance(wps[2 + k].local, orbit.orbit->centre), 10.0, 1e-6);
    }
    EXPECT_DOUBLE_EQ(wps[2 + orbit_n].speed, 4.0);
    // Second iteration starts again at the repeat's first waypoint, at the speed left by the last iteration.
    const std::size_t body = 1 + orbit_n + 1;
    EXPECT_EQ(wps[1 + body].element, wps[1].element);
    EXPECT_DOUBLE_EQ(wps[1 + body].speed, 1.5);
    // The timed hold follows the four iterations.
    const auto& hold = wps[1 + 4 * body];
    EXPECT_EQ(hold.action, WaypointAction::HoldFor);
    EXPECT_DOUBLE_EQ(hold.hold_seconds, 12.0);
    EXPECT_FALSE(hold.has_position);
    EXPECT_EQ(plan->element_path(hold.element), "plan.elements[3]");
    std::size_t until_released = 0;
    for (const auto& w : wps) {
        until_released += w.action == WaypointAction::HoldUntilReleased;
    }
    EXPECT_EQ(until_released, 6u);
}

TEST(FlightplanExpander, SeekAndRestoreMatchAFullExpansion) {
    auto plan = load(kMixedPlan);
    ASSERT_TRUE(plan);
    const auto all = expand_all(plan);
    std::mt19937 rng(3);
    Expander e(plan);
    for (int k = 0; k < 300; ++k) {
        const std::uint64_t n = std::uniform_int_distribution<std::uint64_t>(0, all.size() - 1)(rng);
        ASSERT_TRUE(e.seek(n)) << n;
        for (std::uint64_t i = n; i < std::min<std::uint64_t>(n + 3, all.size()); ++i) {
            auto w = e.next();
            ASSERT_TRUE(w);
            EXPECT_EQ(w->index, i);
            EXPECT_EQ(w->element, all[i].element) << i;
            EXPECT_EQ(w->local, all[i].local) << i;
            EXPECT_DOUBLE_EQ(w->speed, all[i].speed) << i;
            EXPECT_EQ(w->action, all[i].action) << i;
        }
    }
    EXPECT_FALSE(e.seek(all.size()));
    Expander fresh(plan);
    ASSERT_TRUE(fresh.restore({}, 17));
    EXPECT_EQ(fresh.next()->local, all[17].local);
}

// A skip past the end is refused and loses nothing: the stream gives what it would have given next (it
// had moved to its end, and a window fed from it then never drove the waypoints it had not yet read).
TEST(FlightplanExpander, ASeekPastTheEndLeavesTheStreamWhereItWas) {
    auto plan = load(kMixedPlan);
    ASSERT_TRUE(plan);
    const auto all = expand_all(plan);
    ASSERT_GT(all.size(), 12u);
    Expander e(plan);
    for (int i = 0; i < 10; ++i) {
        e.next();
    }
    EXPECT_FALSE(e.seek(all.size() + 5000));
    EXPECT_EQ(e.position(), 10u);
    auto w = e.next();
    ASSERT_TRUE(w);
    EXPECT_EQ(w->index, 10u);
    EXPECT_EQ(w->local, all[10].local);
}

TEST(FlightplanExpander, JumpIntoDetachedBlockThenGotoBackIntoLoop) {
    auto plan = load(kMixedPlan);
    ASSERT_TRUE(plan);
    Expander e(plan);
    for (int i = 0; i < 5; ++i) {
        e.next();
    }
    ASSERT_TRUE(e.jump_to("home-run"));
    const auto origin = e.origin();
    EXPECT_EQ(origin.index, 5u);
    auto w = e.next();
    ASSERT_TRUE(w);
    EXPECT_EQ(w->index, 5u);
    EXPECT_EQ(plan->element_path(w->element), "plan.blocks[0].elements[0]");
    // The goto lands on 'r' inside a repeat of 3: r, (x, hold) x2, then two more iterations, then the last
    // waypoint of the plan; the detached block does not run again.
    std::vector<Waypoint> rest;
    while (auto n = e.next()) {
        rest.push_back(*n);
    }
    EXPECT_EQ(rest.size(), 3u * 5u + 1u);
    EXPECT_EQ(plan->element_name(rest[0].element), "r");
    // Restore reproduces the stream after the jump.
    Expander again(plan);
    ASSERT_TRUE(again.restore(origin, 8));
    EXPECT_EQ(again.next()->local, rest[2].local);
    EXPECT_FALSE(again.restore(origin, 4));  // before the jump: not part of this stream
}

TEST(FlightplanExpander, ForeverRepeatSeeksFarInConstantTime) {
    auto plan = load(R"(plan:
  name: forever
  elements:
    - waypoint: {lat: 41.0, lon: 2.0}
    - repeat:
        count: forever
        elements:
          - waypoint: {lat: 41.0001, lon: 2.0}
          - waypoint: {lat: 41.0001, lon: 2.0001}
          - speed: 2.5
          - waypoint: {lat: 41.0, lon: 2.0001}
)");
    ASSERT_TRUE(plan);
    Expander e(plan);
    const std::uint64_t far = 3'000'000'000'000ull + 2;  // 1 + 3 * 1e12 + 1: second waypoint of an iteration
    ASSERT_TRUE(e.seek(far));
    auto w = e.next();
    ASSERT_TRUE(w);
    EXPECT_EQ(w->index, far);
    EXPECT_EQ(plan->element_path(w->element), "plan.elements[1].repeat.elements[1]");
    EXPECT_DOUBLE_EQ(w->speed, 2.5);  // set by the previous iteration
}

TEST(FlightplanExpander, StopsOnALegIntoANoFlyZoneAddedAfterValidation) {
    auto loaded = load(kScanPlan);
    ASSERT_TRUE(loaded);
    auto plan = std::make_shared<Plan>(*loaded);
    NoFlyZone zone;
    zone.name = "late-zone";
    zone.local = {{40, 40}, {60, 40}, {60, 60}, {40, 60}};
    plan->no_fly.push_back(zone);
    Expander e(plan);
    std::size_t produced = 0;
    while (e.next()) {
        ++produced;
    }
    ASSERT_TRUE(e.error().has_value());
    EXPECT_NE(e.error()->find("late-zone"), std::string::npos);
    EXPECT_LT(produced, plan->count(plan->children(plan->main_list)[0]).value());
    EXPECT_FALSE(e.next().has_value());
}

TEST(FlightplanExpander, MillionWaypointScanStreamsInSmallMemory) {
    // 1 km x 1 km at 4 m spacing, 4 m step: 250 lines of 251 points. The bench runs the million; here the
    // point is the exact count and the step bound while streaming line by line.
    auto plan = load(R"(plan:
  name: big
  elements:
    - scan: {rectangle: {sw: [41.0, 2.0], ne: [41.009, 2.012]}, spacing: 4, step: 4, heading: 0}
)");
    ASSERT_TRUE(plan);
    const std::uint32_t scan_id = plan->children(plan->main_list)[0];
    Expander e(plan);
    std::uint64_t n = 0;
    Enu last{};
    double max_gap = 0;
    while (auto w = e.next()) {
        if (n > 0) {
            max_gap = std::max(max_gap, distance(last, w->local));
        }
        last = w->local;
        ++n;
    }
    EXPECT_EQ(n, plan->count(scan_id).value());
    EXPECT_GT(n, 60'000u);
    EXPECT_LE(max_gap, 4.0 + 1e-6);
    EXPECT_EQ(sizeof(Expander) < 512, true);
}

}  // namespace
}  // namespace airseg::flightplan
