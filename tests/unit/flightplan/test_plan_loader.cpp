// The YAML plan loader: example plans load, every error of a plan is reported at once with file:line:col
// and element path, no-fly legs are rejected with their buffer.
#include <gtest/gtest.h>

#include <filesystem>

#include "services/flightplan/plan_loader.hpp"
#include "tests/support/tree_paths.hpp"
#include "tests/unit/flightplan/plan_text.hpp"

namespace airseg::flightplan {
namespace {

using test::messages;

TEST(FlightplanLoader, ExamplePlansLoad) {
    int loaded = 0;
    for (const auto& entry :
         std::filesystem::directory_iterator(::airseg::test::source_dir() + "/config/plans")) {
        if (entry.path().extension() != ".yaml") {
            continue;
        }
        const auto r = load_plan_file(entry.path().string());
        EXPECT_TRUE(r.ok()) << entry.path() << "\n" << to_string(r.errors);
        ++loaded;
    }
    EXPECT_GE(loaded, 3);
}

TEST(FlightplanLoader, ExampleSurveyHasTheExpectedShape) {
    const auto r = load_plan_file(::airseg::test::source_dir() + "/config/plans/rover-survey.yaml");
    ASSERT_TRUE(r.ok()) << to_string(r.errors);
    const Plan& p = *r.plan;
    EXPECT_EQ(p.name, "campus-survey");
    EXPECT_EQ(p.vehicle.type, "rover");
    EXPECT_DOUBLE_EQ(p.vehicle.min_spacing, 4.0);
    EXPECT_DOUBLE_EQ(p.vehicle.cruise_speed, 1.5);
    EXPECT_TRUE(p.vehicle.cruise_speed_given);
    EXPECT_DOUBLE_EQ(p.vehicle.commanded_cruise_speed(), 1.5);
    ASSERT_EQ(p.no_fly.size(), 1u);
    EXPECT_DOUBLE_EQ(p.no_fly[0].buffer, 5.0);
    ASSERT_TRUE(p.reactions.link_loss.has_value());
    EXPECT_EQ(p.reactions.link_loss->action, ReactionAction::GotoBlock);
    EXPECT_EQ(p.element_path(p.reactions.link_loss->target_node), "plan.blocks[0]");
    EXPECT_DOUBLE_EQ(p.reactions.link_loss_seconds, 30.0);
    const auto field = p.find("field");
    ASSERT_NE(field, kNoNode);
    EXPECT_EQ(p.element_path(field), "plan.elements[3]");
    EXPECT_EQ(p.nodes[field].mark.line, 23);
    ASSERT_TRUE(p.extra(field).scan.has_value());
    const auto patrol = p.find("patrol");
    ASSERT_NE(patrol, kNoNode);
    EXPECT_EQ(p.count(patrol), 6u);
}

TEST(FlightplanLoader, ReportsEveryErrorAtOnceWithLocation) {
    const std::string text = R"(plan:
  name: broken
  colour: red
  elements:
    - waypoint: {lat: 95, lon: 1.98}
    - scan:
        rectangle: {sw: [41.0, 2.0], ne: [41.001, 2.001]}
        spacing: 0
    - waypoint: {lat: 41.0, lon: 2.0, sped: 3}
    - goto: nowhere
    - hold: {lat: 41.0, lon: 2.0}
)";
    const auto r = load_plan_text(text, "broken.yaml");
    ASSERT_FALSE(r.ok());
    const std::vector<std::string> expected = {
        "broken.yaml:3:3: plan.colour: unknown field (expected one of: name, vehicle, reference, home, "
        "no_fly, "
        "geofence, reactions, elements, blocks)",
        "broken.yaml:5:23: plan.elements[0].waypoint.lat: must be between -90 and 90 (got 95)",
        "broken.yaml:8:18: plan.elements[1].scan.spacing: must be > 0 (got 0)",
        "broken.yaml:9:39: plan.elements[2].waypoint.sped: unknown field (did you mean 'speed'?) (expected "
        "one of: name, lat, lon, "
        "alt, "
        "speed, radius)",
        "broken.yaml:11:13: plan.elements[4].hold: needs exactly one of: seconds, until_released: true",
    };
    EXPECT_EQ(messages(r), expected);
}

TEST(FlightplanLoader, UnknownGotoTargetAndDuplicateNames) {
    const std::string text = R"(plan:
  name: names
  elements:
    - waypoint: {name: a, lat: 41.0, lon: 2.0}
    - waypoint: {name: a, lat: 41.001, lon: 2.0}
    - goto: nowhere
  reactions:
    link_loss: {after: 10, action: goto, target: missing}
)";
    const auto r = load_plan_text(text, "names.yaml");
    ASSERT_FALSE(r.ok());
    const auto m = messages(r);
    ASSERT_EQ(m.size(), 3u) << to_string(r.errors);
    EXPECT_EQ(m[0],
              "names.yaml:5:7: plan.elements[1].name: duplicate name 'a' (first used at plan.elements[0])");
    EXPECT_EQ(m[1], "names.yaml:6:7: plan.elements[2].goto: target 'nowhere' is not the name of any element");
    EXPECT_EQ(
        m[2],
        "names.yaml:8:16: plan.reactions.link_loss.target: target 'missing' is not the name of any element");
}

TEST(FlightplanLoader, YamlSyntaxErrorIsLocated) {
    const auto r = load_plan_text("plan:\n  name: [unclosed\n", "syntax.yaml");
    ASSERT_EQ(r.errors.size(), 1u);
    EXPECT_EQ(r.errors[0].file, "syntax.yaml");
    EXPECT_GT(r.errors[0].line, 0);
    EXPECT_NE(r.errors[0].message.find("YAML syntax error"), std::string::npos);
}

TEST(FlightplanLoader, GarbageNeverCrashes) {
    const char* inputs[] = {"",
                            "42",
                            "plan: 7",
                            "plan: {elements: 3}",
                            "plan: {name: x, elements: [[1, 2]]}",
                            "plan: {name: x, elements: [{waypoint: [1, 2]}]}",
                            "- - -",
                            "plan: {name: {a: b}}",
                            "plan: {name: x, elements: [{scan: {polygon: [[1], [2, 3], 4]}}]}"};
    for (const char* in : inputs) {
        const auto r = load_plan_text(in, "garbage.yaml");
        EXPECT_FALSE(r.ok()) << in;
        EXPECT_FALSE(r.errors.empty()) << in;
    }
}

std::string plan_with_leg_near_zone(double buffer) {
    // The leg runs east along 41.0000; the zone starts ~3.3 m north of it.
    return R"(plan:
  name: zone
  no_fly:
    - name: barn
      buffer: )" +
           std::to_string(buffer) +
           R"(
      polygon: [[41.00003, 2.0005], [41.0002, 2.0005], [41.0002, 2.0007], [41.00003, 2.0007]]
  elements:
    - waypoint: {lat: 41.0, lon: 2.0}
    - waypoint: {lat: 41.0, lon: 2.0012}
)";
}

TEST(FlightplanLoader, LegCrossingNoFlyBufferIsRejected) {
    const auto rejected = load_plan_text(plan_with_leg_near_zone(5.0), "zone.yaml");
    ASSERT_FALSE(rejected.ok());
    ASSERT_EQ(rejected.errors.size(), 1u);
    EXPECT_EQ(rejected.errors[0].path, "plan.elements[1]");
    EXPECT_EQ(rejected.errors[0].line, 9);
    EXPECT_NE(rejected.errors[0].message.find("no-fly zone 'barn'"), std::string::npos);
    EXPECT_TRUE(load_plan_text(plan_with_leg_near_zone(1.0), "zone.yaml").ok());
}

TEST(FlightplanLoader, ScanLegsThroughAZoneAreRejected) {
    const std::string text = R"(plan:
  name: scan-zone
  no_fly:
    - name: shed
      polygon: [[41.0002, 2.0002], [41.0003, 2.0002], [41.0003, 2.0003], [41.0002, 2.0003]]
  elements:
    - scan: {rectangle: {sw: [41.0, 2.0], ne: [41.001, 2.001]}, spacing: 10}
)";
    const auto r = load_plan_text(text, "scan-zone.yaml");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.errors[0].path, "plan.elements[0]");
}

TEST(FlightplanLoader, VehicleProfileBoundsSpacing) {
    const std::string text = R"(plan:
  name: plane
  vehicle: {type: plane}
  elements:
    - scan: {rectangle: {sw: [41.0, 2.0], ne: [41.01, 2.01]}, spacing: 20}
)";
    const auto r = load_plan_text(text, "plane.yaml");
    ASSERT_EQ(r.errors.size(), 1u) << to_string(r.errors);
    EXPECT_EQ(r.errors[0].path, "plan.elements[0].scan.spacing");
    EXPECT_NE(r.errors[0].message.find("min_spacing"), std::string::npos);
}

TEST(FlightplanLoader, LoopsWithoutWaypointsAreRejected) {
    const auto forever = load_plan_text(R"(plan:
  name: empty-loop
  elements:
    - waypoint: {lat: 41.0, lon: 2.0}
    - repeat: {count: forever, elements: [{speed: 2}]}
)",
                                        "loop.yaml");
    ASSERT_FALSE(forever.ok());
    EXPECT_NE(forever.errors[0].message.find("produces no waypoints"), std::string::npos);
    const auto cycle = load_plan_text(R"(plan:
  name: goto-cycle
  elements:
    - waypoint: {lat: 41.0, lon: 2.0}
    - speed: {name: again, value: 2}
    - goto: again
)",
                                      "cycle.yaml");
    ASSERT_FALSE(cycle.ok());
    EXPECT_NE(cycle.errors[0].message.find("goto cycle"), std::string::npos);
}

}  // namespace
}  // namespace airseg::flightplan

namespace airseg::flightplan {
namespace {

TEST(FlightplanLoader, RepeatWrapLegAndTheLegAfterALongRepeatAreChecked) {
    // A -> B -> C repeated 100000 times: only the wrap leg C -> A crosses 'middle'; the leg from C to D after
    // the repeat crosses 'east'. Validation folds the repeat, so this is quick and still finds both.
    const std::string text = R"(plan:
  name: wrap
  no_fly:
    - name: middle
      polygon: [[41.00045, 2.00055], [41.00055, 2.00055], [41.00055, 2.00065], [41.00045, 2.00065]]
    - name: east
      polygon: [[41.0009, 2.0015], [41.0011, 2.0015], [41.0011, 2.0016], [41.0009, 2.0016]]
  elements:
    - repeat:
        count: 100000
        elements:
          - waypoint: {lat: 41.0, lon: 2.0}
          - waypoint: {lat: 41.001, lon: 2.0}
          - waypoint: {lat: 41.001, lon: 2.0012}
    - waypoint: {lat: 41.001, lon: 2.002}
)";
    const auto r = load_plan_text(text, "wrap.yaml");
    ASSERT_EQ(r.errors.size(), 2u) << to_string(r.errors);
    EXPECT_EQ(r.errors[0].path, "plan.elements[0].repeat.elements[0]");
    EXPECT_NE(r.errors[0].message.find("'middle'"), std::string::npos);
    EXPECT_EQ(r.errors[1].path, "plan.elements[1]");
    EXPECT_NE(r.errors[1].message.find("waypoint 300000 "), std::string::npos) << r.errors[1].message;
    EXPECT_NE(r.errors[1].message.find("'east'"), std::string::npos);
}

}  // namespace
}  // namespace airseg::flightplan

#include <fstream>
#include <random>

#include "services/flightplan/expander.hpp"

namespace airseg::flightplan {
namespace {

TEST(FlightplanLoader, MutatedPlansNeverCrash) {
    std::ifstream in(::airseg::test::source_dir() + "/config/plans/rover-survey.yaml", std::ios::binary);
    const std::string original((std::istreambuf_iterator<char>(in)), {});
    ASSERT_FALSE(original.empty());
    const std::string alphabet = "{}[]:,-&*#!|>'\"\n 0123456789.e-+~";
    std::mt19937 rng(123);
    int accepted = 0;
    for (int k = 0; k < 300; ++k) {
        std::string t = original;
        const int edits = 1 + static_cast<int>(rng() % 4);
        for (int e = 0; e < edits && !t.empty(); ++e) {
            const std::size_t pos = rng() % t.size();
            switch (rng() % 4) {
                case 0:
                    t.erase(pos, 1);
                    break;
                case 1:
                    t.insert(pos, 1, alphabet[rng() % alphabet.size()]);
                    break;
                case 2:
                    if (std::isdigit(static_cast<unsigned char>(t[pos]))) {
                        t[pos] = static_cast<char>('0' + rng() % 10);
                    }
                    break;
                default:
                    t.insert(pos, t.substr(pos, rng() % 40));
                    break;
            }
        }
        const auto r = load_plan_text(t, "mutated.yaml");
        if (!r.ok()) {
            EXPECT_FALSE(r.errors.empty());
            continue;
        }
        ++accepted;
        Expander e(r.plan);
        for (int i = 0; i < 2000 && e.next(); ++i) {
        }
    }
    EXPECT_GT(accepted, 0);
}

TEST(FlightplanLoader, AliasExplosionIsBounded) {
    // Seven levels of ten aliases each: 10^7 elements described in a few hundred bytes.
    std::string text =
        "plan:\n  name: bomb\n  blocks:\n    - name: b0\n      elements: &e0 [{waypoint: {lat: 41.0, lon: "
        "2.0}}]\n";
    for (int level = 1; level <= 7; ++level) {
        text +=
            "    - name: b" + std::to_string(level) + "\n      elements: &e" + std::to_string(level) + " [";
        for (int i = 0; i < 10; ++i) {
            text += std::string(i ? ", " : "") + "{repeat: {count: 1, elements: *e" +
                    std::to_string(level - 1) + "}}";
        }
        text += "]\n";
    }
    text += "  elements: *e7\n";
    LoadOptions options;
    options.max_elements = 2000;
    const auto r = load_plan_text(text, "bomb.yaml", options);
    ASSERT_FALSE(r.ok());
    bool bounded = false;
    for (const auto& d : r.errors) {
        bounded = bounded || d.message.find("more than 2000 elements") != std::string::npos;
    }
    EXPECT_TRUE(bounded) << to_string(r.errors);
}

TEST(FlightplanLoader, HugeScanIsRefusedNotComputed) {
    const auto r = load_plan_text(R"(plan:
  name: huge
  vehicle: {min_spacing: 0.1}
  elements:
    - scan: {rectangle: {sw: [-60.0, -170.0], ne: [60.0, 170.0]}, spacing: 0.1}
)",
                                  "huge.yaml");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.errors[0].path, "plan.elements[0].scan.spacing");
}

}  // namespace
}  // namespace airseg::flightplan
