// The plan's main list cut out of the text and read in batches (list_splice.hpp): where the cut is made,
// which layouts are left alone, and that any batch size loads the same plan and the same diagnostics, at the
// same lines, as reading the list unsplit.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "services/flightplan/list_splice.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "tests/unit/flightplan/plan_text.hpp"

namespace airseg::flightplan {
namespace {

using test::messages;

std::string waypoints(std::size_t n, const std::string& indent) {
    std::string out;
    for (std::size_t i = 0; i < n; ++i) {
        out += indent + "- waypoint: {lat: 41." + std::to_string(100 + i) + ", lon: 2.1}\n";
    }
    return out;
}

TEST(ListSplice, CutsTheMainListIntoBatchesOfWholeLines) {
    const std::string text = "plan:\n  name: cut\n  elements:   # the route\n" + waypoints(5, "    ") +
                             "  vehicle: {type: rover}\n";
    const auto splice = find_list_splice(text, 2);
    ASSERT_TRUE(splice.has_value());
    EXPECT_EQ(text.substr(splice->cut_begin - 9, 9), "elements:");
    EXPECT_EQ(text.substr(splice->cut_end, 12), "\n  vehicle: ");
    EXPECT_EQ(splice->cut_lines, 5);
    ASSERT_EQ(splice->batches.size(), 3u);
    EXPECT_EQ(splice->batches[0].first_line, 3);
    EXPECT_EQ(splice->batches[1].first_line, 5);
    EXPECT_EQ(splice->batches[2].first_line, 7);
    EXPECT_EQ(splice->batches[2].end, splice->cut_end + 1);  // with its line break

    SplicedBuffer buffer(text, *splice);
    std::ostringstream seen;
    seen << &buffer;
    EXPECT_EQ(seen.str(), "plan:\n  name: cut\n  elements: []\n  vehicle: {type: rover}\n");

    // A mark after the stand-in moves back to where its text really is.
    YAML::Mark vehicle;
    vehicle.line = 3;
    vehicle.column = 2;
    vehicle.pos = static_cast<int>(seen.str().find("vehicle"));
    const YAML::Mark original = splice->original(vehicle);
    EXPECT_EQ(original.line, 8);
    EXPECT_EQ(original.column, 2);
    EXPECT_EQ(text.substr(static_cast<std::size_t>(original.pos), 7), "vehicle");
}

TEST(ListSplice, ListsAtTheKeysColumnAndAtTheEndOfTheTextAreCut) {
    const std::string compact = "---\nplan:\n  elements:\n" + waypoints(3, "  ");
    const auto splice = find_list_splice(compact.substr(0, compact.size() - 1), 1);
    ASSERT_TRUE(splice.has_value());
    EXPECT_EQ(splice->batches.size(), 3u);
    EXPECT_EQ(splice->cut_end, compact.size() - 1);
}

TEST(ListSplice, OtherLayoutsAreLeftAlone) {
    const std::string list = waypoints(4, "    ");
    const std::vector<std::string> alone = {
        "plan:\n  elements:\n" + list,  // four items in batches of four: nothing to gain
        "name: first\nplan:\n  elements:\n" + list,
        "plan: &p\n  elements:\n" + list,
        "plan:\n  elements: &e\n" + list,
        "plan:\n  elements:\n" + list + "    - waypoint: *home\n",
        "plan:\n  elements:\n" + list + "    # see &x\n",
        "plan:\n  elements: [{waypoint: {lat: 1, lon: 2}}]\n",
        "plan:\n  elements:\n" + list + "\t- waypoint: {lat: 1, lon: 2}\n",
        "plan:\r\n  elements:\r\n" + list,
        "plan:\n  elements:\n" + list + "    - hold: {name: \"gate\"}\n",
        "plan:\n  elements:\n" + list + "    - a plain scalar item\n",
        "plan:\n  elements:\n" + list + "    - hold: {seconds: 1}\n      stray words\n",
        "plan:\n  elements:\n" + list + "    - repeat:\n        :not a key\n",
        "plan:\n  elements:\n" + list + "    - {hold: {seconds: 1}}\n",
        "plan:\n  elements:\n" + list + "    - hold: {name: it's}\n",
        "plan:\n  elements:\n" + list + "    - hold: {name: \xff}\n",
        "plan:\n  elements:\n" + list + "    - hold: {name: \xc0\xaf}\n",
        "plan:\n  elements:\n" + list + "    - hold: {name: a" + std::string(1, '\0') + "b}\n",
        "plan:\n  blocks:\n    - name: b\n      elements:\n" + waypoints(8, "        "),
        "plan: {elements: []}\n",
        "plan:\n  elements:\n      - waypoint: {lat: 1, lon: 2}\n" + waypoints(4, "      ") + "    name: x\n",
        "",
    };
    for (const auto& text : alone) {
        EXPECT_FALSE(find_list_splice(text, text.empty() ? 1 : 4).has_value()) << text;
    }
    EXPECT_TRUE(find_list_splice("plan:\n  elements:\n" + list, 3).has_value());
    EXPECT_TRUE(
        find_list_splice("plan:\n  elements:\n" + list + "    - hold: {name: Plaça \xf0\x9f\x9a\x80}\n", 3)
            .has_value());
}

/// Everything the loader keeps of a plan, one line per node.
std::string describe(const LoadResult& r) {
    if (!r.ok()) {
        std::string out;
        for (const auto& m : messages(r)) {
            out += m + "\n";
        }
        return out;
    }
    const Plan& plan = *r.plan;
    std::ostringstream out;
    out.precision(12);
    out << plan.name << " " << plan.vehicle.cruise_speed << " " << plan.nodes.size() << "\n";
    for (std::uint32_t id = 0; id < plan.nodes.size(); ++id) {
        const Node& n = plan.nodes[id];
        out << to_string(n.kind) << " " << plan.element_path(id) << " @" << n.mark.line << ":" << n.mark.col
            << " parent " << n.parent << " " << n.geo.lat << "," << n.geo.lon << " alt "
            << n.alt().value_or(-1);
        if (n.has_extra) {
            const NodeExtra& x = plan.extra(id);
            out << " name '" << x.name << "' children " << x.children.size() << " speed "
                << x.speed.value_or(-1) << " hold " << x.hold_seconds.value_or(-1) << " repeat "
                << x.repeat_count.value_or(0) << " goto " << x.goto_target;
        }
        out << "\n";
    }
    return out.str();
}

// Items of every kind the list may hold, some multi-line, some wrong in a way the loader reports, some
// that trap a cut made by lines (a quoted scalar or a flow mapping running over an item's line).
const std::vector<std::string> kItems = {
    "- waypoint: {lat: 41.0, lon: 2.0}\n",
    "- waypoint:\n    lat: 41.001\n    lon: 2.0\n    alt: 12\n",
    "- hold: {seconds: 5, name: \"wait here\"}\n",
    "- repeat:\n    count: 2\n    elements:\n      - waypoint: {lat: 41.002, lon: 2.001}\n"
    "      - waypoint: {lat: 41.003, lon: 2.001}\n",
    "- waypoint: {lat: 41.004,\n    lon: 2.002}\n",
    "- waypoint: {lat: 91, lon: 2.0}\n",
    "- waypoint: {lat: 41.0, lon: 2.0}\n  speed: 3\n",
    "- goto: nowhere\n",
    "- hold: {name: \"two\n    lines\"}\n",
    "# a comment between items\n",
    "- speed: 2.5\n",
    "- hold: {name: \"an item\n- hold: {seconds: 1}\n  inside\"}\n",
    "- waypoint: {lat: [1, 2}\n",
    "- waypoint: {lat: 41.005, lon: 2.0, speed: -1}\n",
    "- repeat:\n    count: 2\n    elements:\n",  // a null at the item's end takes the next token's mark
};

std::string indent(const std::string& item, const std::string& by) {
    std::string out;
    std::size_t at = 0;
    while (at < item.size()) {
        const std::size_t brk = item.find('\n', at);
        const std::string line = item.substr(at, brk - at);
        out += (line.empty() || line[0] == '#' ? "" : by) + line + "\n";
        at = brk + 1;
    }
    return out;
}

TEST(ListSplice, AnyBatchSizeLoadsWhatTheUnsplitListLoads) {
    // Documents of 4 to 9 items drawn from kItems, in two list layouts, with fields before and after the
    // list.
    const std::vector<std::string> heads = {"", "  vehicle: {type: rover, cruise_speed: 3}\n"};
    const std::vector<std::string> tails = {"",
                                            "  blocks:\n    - name: nowhere\n      elements:\n"
                                            "        - waypoint: {lat: 41.1, lon: 2.1}\n",
                                            "  blocks:\n    - name: bad\n      elements:\n"
                                            "        - waypoint: {lat: 41.1}\n",
                                            "  vehicle: {type: submarine}\n"};
    std::size_t spliced = 0;
    for (std::size_t seed = 0; seed < 160; ++seed) {
        const bool compact = seed % 2 == 1;
        std::string text =
            "plan:\n  name: diff-" + std::to_string(seed) + "\n" + heads[seed / 2 % 2] + "  elements:\n";
        const std::size_t n = 4 + seed % 6;
        bool trapped = false;
        std::size_t items = 0;
        for (std::size_t k = 0; k < n; ++k) {
            // Mostly plain waypoints, so that most documents load; every item kind shows up.
            const std::size_t pick = (seed * 7 + k * 13) % (2 * kItems.size());
            const std::string& item = pick < kItems.size() ? kItems[pick] : kItems[pick % 2];
            trapped = trapped || item.find_first_of("\"[") != std::string::npos;  // quotes: read unsplit
            text += indent(item, compact ? "  " : "    ");
        }
        text += tails[seed % tails.size()];
        LoadOptions unsplit;
        unsplit.splice_batch_items = 0;
        const auto expected = load_plan_text(text, "diff.yaml", unsplit);
        ASSERT_NE(expected.reading, PlanReading::Spliced);
        for (const std::size_t batch : {1u, 2u, 3u}) {
            LoadOptions options;
            options.splice_batch_items = batch;
            const auto got = load_plan_text(text, "diff.yaml", options);
            EXPECT_EQ(describe(got), describe(expected)) << "batches of " << batch << ":\n" << text;
            // Only a trap, a document the reader cannot stream at all or a list of one batch is read unsplit.
            if (expected.reading == PlanReading::Streamed && !trapped && items > batch) {
                EXPECT_EQ(got.reading, PlanReading::Spliced) << "batches of " << batch << ":\n" << text;
            }
            spliced += got.reading == PlanReading::Spliced ? 1 : 0;
        }
    }
    // The comparison means something only if many documents were in fact read in batches.
    EXPECT_GT(spliced, 100u);
}

TEST(ListSplice, AListInsideAQuotedScalarIsReadUnsplit) {
    // The lines look like the plan's list, but a quoted key that never closes holds them.
    const std::string text = "plan:\n  name: quoted\n  'name: x\n  elements:\n" + waypoints(4, "    ");
    LoadOptions options;
    options.splice_batch_items = 1;
    ASSERT_TRUE(find_list_splice(text, 1).has_value());
    const auto got = load_plan_text(text, "q.yaml", options);
    options.splice_batch_items = 0;
    const auto expected = load_plan_text(text, "q.yaml", options);
    EXPECT_NE(got.reading, PlanReading::Spliced);
    EXPECT_EQ(describe(got), describe(expected));
    EXPECT_FALSE(got.ok());
}

TEST(ListSplice, ALongListIsReadInBatchesByDefault) {
    const std::string text =
        "plan:\n  name: long\n  vehicle: {type: rover, cruise_speed: 12}\n  elements:\n" +
        waypoints(600, "    ");
    const auto r = load_plan_text(text, "long.yaml");
    ASSERT_TRUE(r.ok()) << to_string(r.errors);
    EXPECT_EQ(r.reading, PlanReading::Spliced);
    EXPECT_EQ(r.plan->children(r.plan->main_list).size(), 600u);
    EXPECT_DOUBLE_EQ(r.plan->vehicle.cruise_speed, 12.0);
    const auto last = r.plan->children(r.plan->main_list).back();
    EXPECT_EQ(r.plan->nodes[last].mark.line, 4 + 600);
}

TEST(ListSplice, AnErrorAfterTheListIsReportedAtItsLine) {
    const std::string text = "plan:\n  name: late\n  elements:\n" + waypoints(6, "    ") +
                             "  blocks:\n    - name: b\n      elements:\n        - waypoint: {lat: 41.1}\n";
    LoadOptions options;
    options.splice_batch_items = 2;
    const auto r = load_plan_text(text, "late.yaml", options);
    EXPECT_EQ(r.reading, PlanReading::Spliced);
    ASSERT_EQ(r.errors.size(), 1u) << to_string(r.errors);
    EXPECT_EQ(r.errors[0].line, 13) << to_string(r.errors);
}

TEST(ListSplice, AListAtTheEndOfATextWithoutALastLineBreakLoadsAsUnsplit) {
    // Found by fuzz_flightplan_loader: an empty last item, then a comment with no line break after it. The
    // item's null takes the mark where yaml-cpp closes its mapping, which depends on that last line.
    const std::string list =
        "  elements:\n    - waypoint: {lat: 41.27530, lon: 1.98700}\n"
        "    - waypoint: {lat: 41.27560, lon: 1.98720, speed: ,20 .radius: 3}\n"
        "    - speed: 1.2\n    - scan:\n";
    for (const std::string end : {"#", "  # no line break", "   ", "", "#\n"}) {
        const std::string text = "plan:\n  name: survey\n" + list + end;
        LoadOptions options;
        options.splice_batch_items = 0;
        const auto expected = load_plan_text(text, "end.yaml", options);
        options.splice_batch_items = 1;
        const auto got = load_plan_text(text, "end.yaml", options);
        EXPECT_EQ(got.reading, PlanReading::Spliced) << text;
        EXPECT_FALSE(got.ok()) << text;
        EXPECT_EQ(describe(got), describe(expected)) << text;
    }
}

}  // namespace
}  // namespace airseg::flightplan
