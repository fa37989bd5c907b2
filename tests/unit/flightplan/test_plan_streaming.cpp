// The loader reads element lists one element at a time; these pin what that must not change: diagnostics and
// their order whatever the key order of the document, nested lists, elements refused as a whole, aliases
// into elements already read, and files read as they are parsed.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "services/flightplan/plan_loader.hpp"
#include "tests/unit/flightplan/plan_text.hpp"

namespace airseg::flightplan {
namespace {

using test::messages;

TEST(FlightplanStreaming, FieldsAfterTheElementsStillApplyToThem) {
    // The vehicle comes last, yet its min_spacing bounds the scan above it.
    const auto r = load_plan_text(R"(plan:
  name: late-vehicle
  elements:
    - scan: {rectangle: {sw: [41.0, 2.0], ne: [41.001, 2.001]}, spacing: 5}
  vehicle: {type: rover, min_spacing: 10}
)",
                                  "late.yaml");
    EXPECT_EQ(messages(r),
              std::vector<std::string>{"late.yaml:4:74: plan.elements[0].scan.spacing: must be >= "
                                       "the vehicle's min_spacing (10.000000 m)"});
}

TEST(FlightplanStreaming, NestedListsKeepPathsLinesAndOrder) {
    const auto r = load_plan_text(R"(plan:
  name: nest
  elements:
    - waypoint: {lat: 41.0, lon: 2.0}
    - repeat:
        count: 2
        elements:
          - waypoint: {lat: 41.001, lon: 2.0}
          - block:
              name: inner
              elements:
                - waypoint: {lat: 91, lon: 2.0}
    - hold: {seconds: 0}
  blocks:
    - name: spare
      elements:
        - repeat: {count: 1, elements: []}
)",
                                  "nest.yaml");
    const std::vector<std::string> expected = {
        "nest.yaml:12:35: plan.elements[1].repeat.elements[1].block.elements[0].waypoint.lat: must be "
        "between -90 "
        "and 90 (got 91)",
        "nest.yaml:13:23: plan.elements[2].hold.seconds: must be > 0 (got 0)",
        "nest.yaml:17:40: plan.blocks[0].elements[0].repeat.elements: must be a non-empty list of elements",
    };
    EXPECT_EQ(messages(r), expected);
}

TEST(FlightplanStreaming, NestedPlanLoadsWithItsShape) {
    const auto r = load_plan_text(R"(plan:
  name: nest
  elements:
    - waypoint: {lat: 41.0, lon: 2.0}
    - repeat:
        name: loop
        count: 3
        elements:
          - waypoint: {lat: 41.001, lon: 2.0}
          - block:
              name: inner
              elements:
                - waypoint: {lat: 41.002, lon: 2.0, alt: 12}
  blocks:
    - name: spare
      elements:
        - waypoint: {lat: 41.003, lon: 2.0}
)",
                                  "nest.yaml");
    ASSERT_TRUE(r.ok()) << to_string(r.errors);
    const Plan& p = *r.plan;
    EXPECT_EQ(p.count(p.main_list), 1u + 3u * 2u);
    const auto inner = p.find("inner");
    ASSERT_NE(inner, kNoNode);
    EXPECT_EQ(p.element_path(inner), "plan.elements[1].repeat.elements[1]");
    const auto deepest = p.children(inner).at(0);
    EXPECT_EQ(p.element_path(deepest), "plan.elements[1].repeat.elements[1].block.elements[0]");
    EXPECT_EQ(p.nodes[deepest].alt(), 12.0);
    EXPECT_EQ(p.nodes[deepest].mark.line, 13);
    EXPECT_EQ(p.element_path(p.find("spare")), "plan.blocks[0]");
    EXPECT_EQ(p.element_path(p.children(p.find("spare")).at(0)), "plan.blocks[0].elements[0]");
    EXPECT_EQ(p.extra(p.find("loop")).repeat_count, 3u);
}

TEST(FlightplanStreaming, AContainerWithASecondKeyIsRefusedAsAWhole) {
    const auto r = load_plan_text(R"(plan:
  name: two-keys
  elements:
    - repeat:
        count: 1
        elements:
          - waypoint: {lat: 95, lon: 2.0}
      name: late
)",
                                  "two.yaml");
    EXPECT_EQ(messages(r), std::vector<std::string>{
                               "two.yaml:4:7: plan.elements[0]: an element is a mapping with exactly one of: "
                               "waypoint, hold, scan, orbit, speed, repeat, block, goto"});
}

TEST(FlightplanStreaming, ContainerFieldsAfterItsElementsCount) {
    const auto r = load_plan_text(R"(plan:
  name: late-count
  elements:
    - repeat:
        elements:
          - waypoint: {lat: 41.0, lon: 2.0}
          - waypoint: {lat: 41.001, lon: 2.0}
        count: 4
)",
                                  "late.yaml");
    ASSERT_TRUE(r.ok()) << to_string(r.errors);
    EXPECT_EQ(r.plan->count(r.plan->main_list), 8u);
}

TEST(FlightplanStreaming, AliasesReachElementsReadEarlier) {
    const auto r = load_plan_text(R"(plan:
  name: aliases
  blocks:
    - name: there-and-back
      elements: &leg
        - waypoint: {lat: 41.001, lon: 2.0}
        - waypoint: {lat: 41.0, lon: 2.0}
  elements:
    - waypoint: &start {lat: 41.0, lon: 2.0}
    - repeat: {count: 2, elements: *leg}
    - waypoint: *start
)",
                                  "aliases.yaml");
    ASSERT_TRUE(r.ok()) << to_string(r.errors);
    EXPECT_EQ(r.plan->count(r.plan->main_list), 1u + 2u * 2u + 1u);
}

TEST(FlightplanStreaming, FileAndTextLoadAlike) {
    const std::string text = R"(plan:
  name: same
  elements:
    - waypoint: {lat: 41.0, lon: 2.0}
    - waypoint: {lat: 41.001, lon: 2.0, speed: 0}
    - goto: nowhere
)";
    const auto file =
        std::filesystem::temp_directory_path() / ("airseg-streaming-" + std::to_string(::getpid()) + ".yaml");
    std::ofstream(file, std::ios::binary) << text;
    const auto from_file = load_plan_file(file.string());
    const auto from_text = load_plan_text(text, file.string());
    std::filesystem::remove(file);
    ASSERT_FALSE(from_file.ok());
    EXPECT_EQ(messages(from_file), messages(from_text));
}

}  // namespace
}  // namespace airseg::flightplan
