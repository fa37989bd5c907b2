// Appending a plan to a running one: the merged text expands like the running plan up to its end, and the
// feeder continues on it without disturbing the autopilot, mid-route and after the plan was done. The
// merge streams; over many layouts of both plans it gives the plan the whole-tree merge gave.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
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
    for (int i = 0; i < count; ++i) {
        o << "    - waypoint: {lat: " << lat + i * 1e-4 << ", lon: 1.98}\n";
    }
    return o.str();
}

using test::load;

std::vector<LatLon> expand(const std::shared_ptr<const Plan>& plan) {
    std::vector<LatLon> out;
    Expander e(plan);
    while (auto w = e.next()) {
        out.push_back(w->position);
    }
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
    for (int i = 0; i < 5; ++i) {
        h.step();
    }
    ASSERT_GT(h.reached.size(), 0u);
    const auto writes_before = h.ap.writes();

    auto merged = append_plan_text(a, line_plan("b", 41.002, 6));
    ASSERT_TRUE(merged.text);
    auto plan_ab = load(*merged.text);
    auto next = std::make_unique<Expander>(plan_ab);
    ASSERT_TRUE(next->restore(running->origin(), running->position()));
    running = next.get();
    const auto generation = h.feeder.progress().generation;
    EXPECT_EQ(h.feeder.progress().extensions, 0u);
    h.feeder.continue_with(PlanFeed{std::move(next), "a"}, h.now);
    EXPECT_EQ(h.ap.writes(), writes_before) << "the window on the autopilot was already right";
    EXPECT_EQ(h.feeder.progress().generation, generation) << "the same plan goes on";
    EXPECT_EQ(h.feeder.progress().extensions, 1u) << "counted, so that the ground hears of the append";
    ASSERT_LT(h.run_until_done(200), 200);
    for (int i = 0; i < 3; ++i) {
        h.step();
    }
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
    EXPECT_EQ(h.feeder.progress().extensions, 2u);
    ASSERT_LT(h.run_until_done(200), 200);
    for (int i = 0; i < 3; ++i) {
        h.step();
    }
    EXPECT_EQ(h.ap.visited(), expand(plan_abc));
    std::vector<std::uint64_t> all(22);
    std::iota(all.begin(), all.end(), 0);
    EXPECT_EQ(h.reached, all);
    EXPECT_EQ(h.feeder.progress().waypoints_reached, 22u);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
    EXPECT_EQ(h.feeder.progress().starvation_holds, 0u);

    h.feeder.replace_plan(PlanFeed{std::make_unique<Expander>(load(a)), "a"}, h.now);
    EXPECT_EQ(h.feeder.progress().extensions, 0u) << "another plan starts with none";
}

// The merge as it was before it streamed (the library keeps it for the layouts that need it) is the
// reference: both plans loaded as whole yaml-cpp trees, the appended lists' items cloned onto the running
// plan's.
MergedPlan whole_tree_merge(std::string_view running, std::string_view appended) {
    return append_plan_text_as_trees(running, appended);
}

/// Everything a loaded plan means, as text: its fields, every element, the waypoints of the main stream and
/// of a jump to each named element. Two plans that read the same here fly the same.
std::string describe(const std::string& text) {
    LoadOptions options;
    options.max_elements = 100'000;
    const auto r = load_plan_text(text, "merged.yaml", options);
    std::ostringstream o;
    o.precision(12);
    if (!r.ok()) {
        for (const auto& d : r.errors) {
            o << "error " << d.path << ": " << d.message << "\n";
        }
        return o.str();
    }
    const Plan& p = *r.plan;
    o << "name " << p.name << "\nvehicle " << p.vehicle.type << ' ' << p.vehicle.min_spacing << ' '
      << p.vehicle.arrival_radius << ' ' << p.vehicle.cruise_speed << ' ' << p.vehicle.cruise_speed_given
      << "\n";
    if (p.home) {
        o << "home " << p.home->lat << ',' << p.home->lon << "\n";
    }
    for (const auto& z : p.no_fly) {
        o << "no_fly " << z.name << ' ' << z.buffer;
        for (const auto& c : z.polygon) {
            o << ' ' << c.lat << ',' << c.lon;
        }
        o << "\n";
    }
    o << "geofence";
    for (const auto& c : p.geofence) {
        o << ' ' << c.lat << ',' << c.lon;
    }
    o << "\n";
    for (const auto* reaction : {&p.reactions.link_loss, &p.reactions.low_battery, &p.reactions.geofence}) {
        if (*reaction) {
            o << "reaction " << to_string((*reaction)->action) << ' ' << (*reaction)->target << "\n";
        }
    }
    std::vector<std::string> names;
    for (std::uint32_t i = 0; i < p.nodes.size(); ++i) {
        const Node& n = p.nodes[i];
        const auto count = p.count(i);
        o << p.element_path(i) << " kind " << static_cast<int>(n.kind) << " name '" << p.element_name(i)
          << "' at " << n.geo.lat << ',' << n.geo.lon << " alt " << n.alt().value_or(NAN) << " count "
          << (count ? std::to_string(*count) : "-") << "\n";
        if (!p.element_name(i).empty()) {
            names.push_back(p.element_name(i));
        }
    }
    auto stream = [&](Expander& e, int limit) {
        for (int i = 0; i < limit; ++i) {
            auto w = e.next();
            if (!w) {
                break;
            }
            o << "  " << w->index << ' ' << e.element_path(w->element) << ' ' << to_string(w->action) << ' '
              << w->position.lat << ',' << w->position.lon << " alt " << w->alt.value_or(NAN) << " speed "
              << w->speed << " hold " << w->hold_seconds << "\n";
        }
        if (e.error()) {
            o << "  stopped: " << *e.error() << "\n";
        }
    };
    o << "stream\n";
    Expander main(r.plan);
    stream(main, 400);
    for (const auto& name : names) {
        Expander e(r.plan);
        o << "jump " << name << ' ' << e.jump_to(name) << "\n";
        stream(e, 40);
    }
    return o.str();
}

bool adds_to(const std::string& appended, const char* list) {
    const YAML::Node value = YAML::Load(appended)["plan"][list];
    return value.IsDefined() && !value.IsNull();
}

struct Sample {
    const char* name;
    std::string text;
    const char* aliased_list = nullptr;  // running plans: a list given as an alias (whole-tree merge)
};

const std::vector<Sample>& running_plans() {
    static const std::vector<Sample> plans = {
        {"block style, all lists", R"(plan:
  name: running
  vehicle: {type: rover, cruise_speed: 1.5}
  home: {lat: 41.0, lon: 2.0}
  reactions:
    link_loss: {after: 20, action: goto, target: lost}
  elements:
    - waypoint: {lat: 41.0001, lon: 2.0001, alt: 5}
    - hold: {lat: 41.0002, lon: 2.0001, seconds: 3}
    - repeat:
        count: 2
        elements:
          - waypoint: {lat: 41.0003, lon: 2.0002}
          - waypoint: {lat: 41.0004, lon: 2.0002}
  blocks:
    - name: lost
      elements:
        - waypoint: {lat: 41.0, lon: 2.0}
  no_fly:
    - name: tower
      polygon: [[41.2, 2.2], [41.2, 2.21], [41.21, 2.21]]
)"},
        {"flow style",
         "plan: {name: flow, elements: [{waypoint: {lat: 41.0001, lon: 2.0003}}, {speed: 1.0}, "
         "{waypoint: {lat: 41.0002, lon: 2.0003}}], no_fly: [{name: pond, buffer: 5, polygon: "
         "[[41.3, 2.3], [41.3, 2.31], [41.31, 2.31]]}]}\n"},
        {"anchors inside and across items", R"(plan:
  name: anchored
  home: &home {lat: 41.0, lon: 2.0}
  elements:
    - waypoint: &first {lat: 41.0001, lon: 2.0004}
    - waypoint: *home
    - &again {waypoint: {lat: 41.0002, lon: 2.0004, alt: 7}}
    - *again
    - waypoint: *first
  blocks:
    - name: back
      elements: [{waypoint: *first}]
)"},
        {"comments", R"(# the running plan
plan:  # its mapping
  name: commented  # trailing
  # before the list
  elements:
    # first
    - waypoint: {lat: 41.0001, lon: 2.0005}  # one
    - waypoint: {lat: 41.0002, lon: 2.0005}
    # after the last item
  # after the list
# at the end
)"},
        {"elements only", "plan:\n  name: bare\n  elements:\n    - waypoint: {lat: 41.0001, lon: 2.0006}\n"},
        {"null lists", R"(plan:
  name: nulls
  elements:
    - waypoint: {lat: 41.0001, lon: 2.0006}
  blocks:
  no_fly: ~
)"},
        {"null elements", "plan:\n  name: nothing yet\n  elements: null\n"},
        {"lists in another order", R"(plan:
  blocks:
    - name: early
      elements:
        - waypoint: {lat: 41.0001, lon: 2.0008}
  no_fly:
    - {name: shed, polygon: [[41.2, 2.3], [41.2, 2.31], [41.21, 2.31]]}
  name: reordered
  elements:
    - waypoint: {lat: 41.0002, lon: 2.0008}
)"},
        {"main list shared with a block", R"(plan:
  name: shared
  elements: &main
    - waypoint: {lat: 41.0001, lon: 2.0009}
    - waypoint: {lat: 41.0002, lon: 2.0009}
  blocks:
    - name: again
      elements: *main
)"},
        {"main list given as an alias",
         R"(plan:
  name: aliased
  blocks:
    - name: route
      elements: &route
        - waypoint: {lat: 41.0001, lon: 2.001}
  elements: *route
)",
         "elements"},
        {"short lines, one-space indent",
         [] {
             // The emitter writes this longer than it is: the merge runs again at the exact size (checked
             // below). 30 lines are enough for that; each line costs every pair a load under qemu.
             std::string t = "plan:\n name: short\n elements:\n";
             for (int i = 0; i < 30; ++i) {
                 t += " - waypoint: {lat: 41.0" + std::to_string(100 + i) + ",lon: 2.0}\n";
             }
             return t;
         }()},
    };
    return plans;
}

const std::vector<Sample>& appended_plans() {
    static const std::vector<Sample> plans = {
        {"block style, all lists", R"(plan:
  name: more
  elements:
    - waypoint: {lat: 41.0011, lon: 2.0011}
    - hold: {seconds: 2}
  blocks:
    - name: extra
      elements:
        - waypoint: {lat: 41.0012, lon: 2.0012}
  no_fly:
    - name: mast
      polygon: [[41.4, 2.4], [41.4, 2.41], [41.41, 2.41]]
)"},
        {"flow style",
         "plan: {name: f, elements: [{waypoint: {lat: 41.0013, lon: 2.0013}}, {speed: 0.5}, "
         "{waypoint: {lat: 41.0014, lon: 2.0013}}], blocks: [{name: fb, elements: "
         "[{waypoint: {lat: 41.0014, lon: 2.0014}}]}]}"},
        {"anchors inside and across items", R"(plan:
  name: inside
  elements:
    - waypoint: &p {lat: 41.0021, lon: 2.0021}
    - waypoint: {lat: 41.0022, lon: 2.0021}
    - waypoint: *p
    - &rep {repeat: {count: 2, elements: [{waypoint: {lat: 41.0023, lon: 2.0022}}]}}
    - *rep
)"},
        {"aliases to nodes outside the items", R"(plan:
  name: outside
  home: &h {lat: 41.0031, lon: 2.0031}
  geofence: &fence [[41.5, 2.5], [41.5, 2.51], [41.51, 2.51]]
  elements:
    - waypoint: &q {lat: 41.0032, lon: 2.0032}
    - waypoint: *h
  blocks:
    - name: home_again
      elements:
        - waypoint: *h
        - waypoint: *q
  no_fly:
    - name: fenced
      buffer: 1
      polygon: *fence
)"},
        {"elements referring to a block's items", R"(plan:
  name: blocks_first
  blocks:
    - name: side
      elements:
        - waypoint: &s {lat: 41.0041, lon: 2.0041}
        - &leg {waypoint: {lat: 41.0042, lon: 2.0041}}
  elements:
    - waypoint: *s
    - *leg
    - waypoint: {lat: 41.0043, lon: 2.0042}
)"},
        {"alias through an alias", R"(plan:
  name: chain
  home: &h {lat: 41.0051, lon: 2.0051}
  blocks:
    - name: loop
      elements: &body
        - waypoint: *h
        - waypoint: {lat: 41.0052, lon: 2.0052}
  elements:
    - repeat: {count: 2, elements: *body}
    - waypoint: *h
)"},
        {"list given as an alias", R"(plan:
  name: list_alias
  blocks:
    - name: b1
      elements: &seq
        - waypoint: {lat: 41.0061, lon: 2.0061}
        - waypoint: {lat: 41.0062, lon: &lon 2.0062}
  elements: *seq
  no_fly: [{name: far, polygon: [[41.6, 2.6], [41.6, 2.61], [41.61, *lon]]}]
)"},
        {"anchor defined twice", R"(plan:
  name: redefined
  elements:
    - waypoint: &a {lat: 41.0071, lon: 2.0071}
    - waypoint: *a
    - waypoint: &a {lat: 41.0072, lon: 2.0072}
    - waypoint: *a
)"},
        {"comments", R"(# appended
plan:
  name: noted  # name
  elements:  # the list
    # an item follows
    - waypoint: {lat: 41.0081, lon: 2.0081}  # here
    # and the last one
    - waypoint: {lat: 41.0082, lon: 2.0081}
  # blocks next
  blocks:
    - name: noted_block  # named
      elements: [{waypoint: {lat: 41.0083, lon: 2.0082}}]
# end
)"},
        {"null lists", R"(plan:
  name: nulls
  elements:
    - waypoint: {lat: 41.0091, lon: 2.0091}
  blocks:
  no_fly: ~
)"},
        {"blocks only", R"(plan:
  name: just_blocks
  blocks:
    - name: spare
      elements:
        - waypoint: {lat: 41.0101, lon: 2.0101}
)"},
        {"empty lists", "plan:\n  name: empty\n  elements: []\n  no_fly: []\n"},
        {"a list key that is not a list", "plan:\n  name: odd\n  no_fly: {}\n  blocks: 5\n"},
        {"tags and quoting", R"(plan:
  name: "quoted: name"
  elements:
    - waypoint: !!map {lat: !!float 41.0111, lon: "2.0111"}
    - waypoint: {lat: 41.0112, lon: '2.0111', alt: "3"}
)"},
    };
    return plans;
}

// The running plans in three cases of their own (plan k in case k mod 3): under qemu-arm on armel, with no
// FPU and the suite beside it, all of them as one case ran past its 60-s limit.
constexpr std::size_t kRunningGroups = 3;
class FlightplanAppendPairs : public ::testing::TestWithParam<std::size_t> {};

TEST_P(FlightplanAppendPairs, StreamingMergeLoadsLikeTheWholeTreeMerge) {
    int loaded = 0, pairs = 0, second_passes = 0;
    bool long_sample = false;
    for (std::size_t i = GetParam(); i < running_plans().size(); i += kRunningGroups) {
        const auto& r = running_plans()[i];
        long_sample = long_sample || std::string_view(r.name).starts_with("short lines");
        for (const auto& a : appended_plans()) {
            SCOPED_TRACE(std::string("running: ") + r.name + "; appended: " + a.name);
            ++pairs;
            const auto want = whole_tree_merge(r.text, a.text);
            const auto got = append_plan_text(r.text, a.text);
            ASSERT_EQ(got.text.has_value(), want.text.has_value()) << got.error << " / " << want.error;
            EXPECT_EQ(got.error, want.error);
            EXPECT_EQ(got.whole_tree, r.aliased_list != nullptr && adds_to(a.text, r.aliased_list));
            if (!want.text) {
                continue;
            }
            // Longer than the first pass's capacity (plan_merge.cpp): written again at its exact size.
            second_passes +=
                got.text && !got.whole_tree && got.text->size() > r.text.size() + a.text.size() + 64;
            const std::string meaning = describe(*want.text);
            EXPECT_EQ(describe(*got.text), meaning) << "merged:\n" << *got.text << "before:\n" << *want.text;
            loaded += meaning.rfind("error ", 0) != 0;
            // Without anchors there is nothing to name differently: the very same text.
            if (r.text.find('&') == std::string::npos && a.text.find('&') == std::string::npos) {
                EXPECT_EQ(*got.text, *want.text);
            }

            // The merged text is the running plan of the next append.
            const std::string& next = appended_plans()[3].text;
            const auto got2 = append_plan_text(*got.text, next);
            const auto want2 = whole_tree_merge(*want.text, next);
            ASSERT_TRUE(got2.text) << got2.error;
            ASSERT_TRUE(want2.text) << want2.error;
            EXPECT_EQ(describe(*got2.text), describe(*want2.text)) << "merged:\n" << *got2.text;
        }
    }
    EXPECT_GT(loaded, pairs / 2) << "too few merged plans load: the comparison says little";
    if (long_sample) {
        EXPECT_GT(second_passes, 0) << "no merge took its second pass: the samples no longer test it";
    }
}

INSTANTIATE_TEST_SUITE_P(RunningPlans, FlightplanAppendPairs,
                         ::testing::Range<std::size_t>(0, kRunningGroups));

TEST(FlightplanAppend, ErrorsAreTheWholeTreeMergeErrors) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"plan", "plan: {}"},
        {"plan: {}", "plan"},
        {"plan", "plan"},
        {"- 1", "plan: {}"},
        {"plan:\n  name: a\n", "- 1\n"},
        {"", "plan: {elements: [1]}"},
        {"plan: {}", ""},
        {"plan: [", "plan: {}"},
        {"plan: {}", "plan: ["},
        {"plan: [", "plan: {"},
        {"plan", "plan: {"},
        {"plan: 5", "plan: {elements: [1]}"},
        {"plan: {}", "plan: [1]"},
        {"other: {}", "plan: {}"},
        {"plan: {elements: 5}", "plan: {elements: [1]}"},
        {"plan: {elements: {a: 1}}", "plan: {no_fly: [1]}"},
        {"plan: {no_fly: {a: 1}}", "plan: {no_fly: [1]}"},
        {"plan: {elements: 5}", "plan: {elements: []}"},
        {"plan: {}", "plan: {elements: *nowhere}"},
        {"plan: {}\n---\nplan: [", "plan: {elements: [1]}"},
        {"plan: 5\nplan: {}", "plan: {elements: [1]}"},
        {"plan: {elements: [1], elements: 5}", "plan: {elements: [2]}"},
    };
    for (const auto& [running, appended] : cases) {
        SCOPED_TRACE("running: " + running + "; appended: " + appended);
        const auto want = whole_tree_merge(running, appended);
        const auto got = append_plan_text(running, appended);
        EXPECT_EQ(got.text, want.text);
        EXPECT_EQ(got.error, want.error);
    }
}

TEST(FlightplanAppend, LayoutsTheStreamCannotFollowAreMergedWhole) {
    const std::string appended = "plan:\n  elements:\n    - waypoint: {lat: 41.0011, lon: 2.0011}\n";
    const std::vector<std::string> running = {
        running_plans()[9].text,  // the main list is an alias: appending to it appends to the anchored list
        "plan:\n  name: k\n  &k elements: [{waypoint: {lat: 41.0, lon: 2.0}}]\n  *k : 1\n",
        "x: &p {name: p, elements: [{waypoint: {lat: 41.0, lon: 2.0}}]}\nplan: *p\n",
    };
    for (const auto& r : running) {
        SCOPED_TRACE(r);
        const auto got = append_plan_text(r, appended);
        const auto want = whole_tree_merge(r, appended);
        EXPECT_TRUE(got.whole_tree);
        EXPECT_EQ(got.text, want.text);
        EXPECT_EQ(got.error, want.error);
    }
    // An appended item that is an alias to the list holding it: its events are not all read yet.
    const std::string running_plan = running_plans()[4].text;
    for (const std::string a : {"plan: &p {name: p, elements: [{waypoint: {lat: 41.0, lon: 2.0}}, *p]}\n",
                                "plan:\n  elements: &e [{waypoint: {lat: 41.0, lon: 2.0}}, {repeat: "
                                "{count: 2, elements: *e}}]\n"}) {
        SCOPED_TRACE(a);
        const auto got = append_plan_text(running_plan, a);
        const auto want = whole_tree_merge(running_plan, a);
        EXPECT_TRUE(got.whole_tree);
        EXPECT_EQ(got.text, want.text);
        EXPECT_EQ(got.error, want.error);
    }
}

TEST(FlightplanAppend, LongRunningPlanGetsTheAppendedElements) {
    auto list = [](const char* name, int count, double lat) {
        std::string text = std::string("plan:\n  name: ") + name + "\n  elements:\n";
        char line[96];
        for (int i = 0; i < count; ++i) {
            std::snprintf(line, sizeof line, "    - waypoint: {lat: %.7f, lon: %.7f}\n",
                          lat + (i / 200) * 5e-5, 2.0 + (i % 200) * 5e-5);
            text += line;
        }
        return text;
    };
    // Long enough that a whole-tree merge would be felt; the 40,000-element figures are bench_flightplan's.
    // Under qemu-arm this size takes 24 s beside the rest of the suite on armhf (a case four times it took a
    // minute), more on armel's soft float: the case stays at 4,000, well inside its 60-s limit there.
    constexpr int kLong = 4'000;
    const auto merged = append_plan_text(list("long", kLong, 41.0), list("tail", 10, 41.5));
    ASSERT_TRUE(merged.text) << merged.error;
    EXPECT_FALSE(merged.whole_tree);
    LoadOptions options;
    options.max_elements = 100'000;
    options.leg_check_limit = 0;
    const auto r = load_plan_text(*merged.text, "merged.yaml", options);
    ASSERT_TRUE(r.ok()) << to_string(r.errors);
    const auto& main = r.plan->children(r.plan->main_list);
    ASSERT_EQ(main.size(), kLong + 10u);
    EXPECT_EQ(r.plan->name, "long");
    EXPECT_EQ(r.plan->nodes[main[kLong - 1]].geo,
              (LatLon{41.0 + ((kLong - 1) / 200) * 5e-5, 2.0 + ((kLong - 1) % 200) * 5e-5}));
    EXPECT_EQ(r.plan->nodes[main[kLong]].geo, (LatLon{41.5, 2.0}));
    EXPECT_EQ(r.plan->nodes[main[kLong + 9]].geo, (LatLon{41.5, 2.0 + 9 * 5e-5}));
}

}  // namespace
}  // namespace airseg::flightplan
