// Hostile plans: texts that are not UTF-8 or hold control characters are refused at the edge with their
// place; files that are not regular files are refused at once; the caps (file size, names, polygon vertices,
// the local frame's reach, the work of laying out scans, listed errors) are enforced with a message naming
// them; a stored plan that no longer loads is set aside at start.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "services/flightplan/persistence.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "services/flightplan/plan_parser.hpp"
#include "services/flightplan/resume.hpp"
#include "tests/support/process.hpp"
#include "tests/unit/flightplan/plan_text.hpp"

namespace airseg::flightplan {
namespace {

// Spelled out: test_persistence.cpp, compiled in the same unity batch, has a TempDir of its own.
using HostileDir = airseg::test::TempDir;

std::string plan_named(const std::string& name) {
    return "plan:\n  name: \"" + name + "\"\n  elements:\n    - {waypoint: {lat: 41.2757, lon: 1.9867}}\n";
}

/// Every error's text dumps as JSON (the status document and the replies carry them).
void expect_dumpable(const LoadResult& r) {
    EXPECT_NO_THROW((void)nlohmann::json(to_string(r.errors)).dump());
}

TEST(FlightplanHostile, InvalidUtf8AnywhereIsRefusedAtItsPlace) {
    // The example of the field report: a name of one byte 0xff.
    auto r = load_plan_text(plan_named("\xff"), "n.yaml");
    ASSERT_FALSE(r.ok());
    ASSERT_EQ(r.errors.size(), 1u);
    EXPECT_EQ(r.errors[0].to_string(),
              "n.yaml:2:10: not valid UTF-8 (byte 0xff): a plan is UTF-8 text without control characters");
    expect_dumpable(r);
    // In a key, an element's name, a comment: the same refusal, wherever it is.
    for (const std::string& text :
         {std::string("plan:\n  n\xe9me: x\n  elements:\n    - {waypoint: {lat: 41.2, lon: 1.9}}\n"),
          std::string(
              "plan:\n  name: p\n  elements:\n    - {waypoint: {name: \"a\xc3\", lat: 41.2, lon: 1.9}}\n"),
          std::string("# \xed\xa0\x80 a surrogate\nplan: {name: p, elements: [{waypoint: {lat: 41.2, lon: "
                      "1.9}}]}\n")}) {
        r = load_plan_text(text, "k.yaml");
        ASSERT_FALSE(r.ok()) << text;
        EXPECT_NE(r.errors[0].message.find("not valid UTF-8"), std::string::npos) << to_string(r.errors);
        expect_dumpable(r);
    }
}

TEST(FlightplanHostile, ANulOrAnotherControlCharacterIsRefusedNotSilentlyTheEndOfThePlan) {
    // yaml-cpp would end the document at the NUL: the plan would silently lose what follows.
    const std::string text =
        std::string("plan:\n  name: p\n  elements:\n    - {waypoint: {lat: 41.2, lon: 1.9}}") + '\0' +
        "\n    - {waypoint: {lat: 95, lon: 1.9}}\n";
    const auto r = load_plan_text(text, "nul.yaml");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.errors[0].line, 4);
    EXPECT_NE(r.errors[0].message.find("a control character (0x00)"), std::string::npos)
        << to_string(r.errors);
    // Tabs and carriage returns are text.
    const auto crlf = load_plan_text(
        "plan:\r\n  name: \"a\tb\"\r\n  elements: [{waypoint: {lat: 41.2, lon: 1.9}}]\r\n", "crlf.yaml");
    EXPECT_TRUE(crlf.ok()) << to_string(crlf.errors);
}

TEST(FlightplanHostile, AFileIsReadOnlyIfItIsARegularFileUpToThePlanCap) {
    HostileDir dir;
    ASSERT_EQ(::mkfifo(dir.file("fifo.yaml").c_str(), 0600), 0);
    const auto started = std::chrono::steady_clock::now();
    for (const auto& [path, why] : std::vector<std::pair<std::string, std::string>>{
             {"/dev/zero", "not a regular file (a character device)"},
             {dir.file("fifo.yaml"), "not a regular file (a FIFO)"},
             {dir.path(), "not a regular file (a directory)"}}) {
        const auto r = load_plan_file(path);
        ASSERT_FALSE(r.ok()) << path;
        EXPECT_EQ(r.errors[0].to_string(), path + ": " + why);
    }
    EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(2))
        << "a read blocked or spun";
    // The same text checks as a text's, read as the file is parsed.
    airseg::test::write_file(dir.file("n.yaml"), plan_named("\xff"));
    const auto r = load_plan_file(dir.file("n.yaml"));
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.errors[0].message.find("not valid UTF-8"), std::string::npos) << to_string(r.errors);
    expect_dumpable(r);
}

TEST(FlightplanHostile, APlanOverTheSizeCapIsRefusedNamingTheCap) {
    const std::string text(kMaxPlanTextBytes + 1, '#');
    const auto r = load_plan_text(text, "big.yaml");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.errors[0].message, "plan larger than the 16 MiB allowed (16777217 bytes)");
}

TEST(FlightplanHostile, ANameLongerThanTheCapIsRefused) {
    const auto r = load_plan_text(plan_named(std::string(kMaxTextBytes + 1, 'n')), "long.yaml");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.errors[0].path, "plan.name");
    EXPECT_EQ(r.errors[0].message, "longer than the 256 bytes allowed (257)");
    EXPECT_TRUE(load_plan_text(plan_named(std::string(kMaxTextBytes, 'n')), "ok.yaml").ok());
}

std::string scan_plan(const std::string& polygon, const std::string& spacing, const std::string& extra = "") {
    return "plan:\n  name: s\n  vehicle: {min_spacing: 0.1}\n" + extra +
           "  elements:\n    - scan: {polygon: " + polygon + ", spacing: " + spacing + "}\n";
}

// A polygon around the whole globe once shrank, in the plan's flat local frame, to a sliver: longitudes are
// taken within ±180° of the reference (179° and -179° are 2° apart), and at a pole a degree of longitude is
// nothing. It loaded as a scan of 780 waypoints. Positions beyond the frame's reach are now refused.
TEST(FlightplanHostile, AWholeGlobeScanIsRefusedNamingTheFramesReach) {
    const auto r =
        load_plan_text(scan_plan("[[-90, -180], [90, -180], [90, 180], [-90, 180]]", "0.1"), "globe.yaml");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.errors[0].message.find("beyond 85 degrees"), std::string::npos) << to_string(r.errors);
    const auto wide =
        load_plan_text(scan_plan("[[-60, -179], [60, -179], [60, 179], [-60, 179]]", "0.1"), "w.yaml");
    ASSERT_FALSE(wide.ok());
    EXPECT_EQ(wide.errors.size(), 1u) << to_string(wide.errors);
    EXPECT_EQ(wide.errors[0].path, "plan.elements[0].scan.polygon[1]");
    EXPECT_NE(wide.errors[0].message.find("km from the plan's reference (-60, -179): every position must lie "
                                          "within 100 km of it"),
              std::string::npos)
        << to_string(wide.errors);
    EXPECT_NE(wide.errors[0].message.find("(and 2 more positions)"), std::string::npos)
        << to_string(wide.errors);
    // A plan tens of kilometres across still loads, with its reference near the middle.
    EXPECT_TRUE(load_plan_text(scan_plan("[[41.0, 1.7], [41.3, 1.7], [41.3, 2.2], [41.0, 2.2]]", "200",
                                         "  reference: {lat: 41.15, lon: 1.95}\n"),
                               "plane.yaml")
                    .ok());
}

TEST(FlightplanHostile, APolygonWithTooManyVerticesIsRefusedNamingTheCap) {
    std::string polygon = "[";
    for (std::size_t i = 0; i <= kMaxPolygonVertices; ++i) {
        const double a = 2 * 3.14159265358979 * static_cast<double>(i) / (kMaxPolygonVertices + 1);
        polygon += (i ? ", [" : "[") + std::to_string(41.2757 + 0.001 * std::sin(a)) + ", " +
                   std::to_string(1.9867 + 0.001 * std::cos(a)) + "]";
    }
    polygon += "]";
    const auto r = load_plan_text(scan_plan(polygon, "5"), "v.yaml");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.errors[0].path, "plan.elements[0].scan.polygon");
    EXPECT_EQ(r.errors[0].message, "has 1001 vertices, more than the 1000 allowed");
}

TEST(FlightplanHostile, ScansThatWouldTakeTooLongToLayOutAreRefusedQuickly) {
    // 50 km of lines 0.1 m apart over a 1000-vertex polygon: 5e8 line-edge crossings, refused before any.
    std::string polygon = "[";
    for (std::size_t i = 0; i < kMaxPolygonVertices; ++i) {
        const double a = 2 * 3.14159265358979 * static_cast<double>(i) / kMaxPolygonVertices;
        polygon += (i ? ", [" : "[") + std::to_string(41.0 + 0.2 * std::sin(a)) + ", " +
                   std::to_string(2.0 + 0.2 * std::cos(a)) + "]";
    }
    polygon += "]";
    const auto started = std::chrono::steady_clock::now();
    const auto r =
        load_plan_text(scan_plan(polygon, "0.1", "  reference: {lat: 41.0, lon: 2.0}\n"), "work.yaml");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.errors[0].path, "plan.elements[0].scan.spacing");
    EXPECT_NE(r.errors[0].message.find("exceed the 40000000 line-edge crossings"), std::string::npos)
        << to_string(r.errors);
    std::cout << "a scan of 5e8 line-edge crossings refused in " << seconds << " s\n";
    // Many scans share the budget: each alone fits, together they do not (a small budget keeps this quick
    // under an emulator).
    std::string many = "plan:\n  name: many\n  vehicle: {min_spacing: 0.1}\n  elements:\n";
    for (int i = 0; i < 5; ++i) {
        many += "    - scan: {rectangle: {sw: [41.0, 2.0], ne: [41.001, 2.001]}, spacing: 0.1}\n";
    }
    LoadOptions options;
    options.max_scan_work = 15000;  // each rectangle: about 840 lines (84 m east-west) of 4 edges
    const auto shared = load_plan_text(many, "many.yaml", options);
    ASSERT_FALSE(shared.ok());
    EXPECT_EQ(shared.errors[0].path, "plan.elements[4].scan.spacing") << to_string(shared.errors);
    EXPECT_NE(shared.errors[0].message.find("with the plan's scans before it"), std::string::npos)
        << to_string(shared.errors);
}

TEST(FlightplanHostile, ErrorListsAreCappedAndLongTextsCut) {
    std::string text = "plan:\n  name: many\n  elements:\n";
    for (int i = 0; i < 200; ++i) {
        text += "    - {waypoint: {lat: 95, lon: 1.9}}\n";
    }
    const auto r = load_plan_text(text, "errors.yaml");
    ASSERT_EQ(r.errors.size(), 200u);
    const auto listed = to_string(r.errors);
    EXPECT_EQ(std::count(listed.begin(), listed.end(), '\n'), 51);
    EXPECT_NE(listed.find("... and 150 more errors\n"), std::string::npos);
    const auto key = load_plan_text("plan:\n  name: p\n  \"" + std::string(100'000, 'k') +
                                        "\": 1\n  elements: [{waypoint: {lat: 41.2, lon: 1.9}}]\n",
                                    "key.yaml");
    ASSERT_FALSE(key.ok());
    EXPECT_LT(to_string(key.errors).size(), 1000u);
}

// A plan accepted by an earlier version (its checksum is right) that no longer loads: set aside at start,
// never resumed, never met again.
TEST(FlightplanHostile, AStoredPlanThatNoLongerLoadsIsSetAside) {
    HostileDir dir;
    StateStore store(dir.file("state"), Durability::NoFsync);
    ASSERT_FALSE(store.save_plan(plan_named("\xff"), "n.yaml"));
    auto resumed = resume_from(store.load());
    EXPECT_FALSE(resumed.resumed);
    EXPECT_TRUE(resumed.set_aside);
    ASSERT_FALSE(resumed.problems.empty());
    EXPECT_NE(resumed.problems.back().find("stored plan no longer loads"), std::string::npos);
    EXPECT_TRUE(store.set_aside_plan().empty());
    EXPECT_FALSE(std::filesystem::exists(store.plan_path()));
    EXPECT_TRUE(std::filesystem::exists(store.plan_path().string() + ".corrupt-1"));
    const auto again = store.load();
    EXPECT_FALSE(again.plan_text);
    EXPECT_TRUE(again.problems.empty());
}

TEST(FlightplanHostile, AStateFileThatIsNotARegularFileIsSetAsideNotRead) {
    HostileDir dir;
    StateStore store(dir.file("state"), Durability::NoFsync);
    std::filesystem::create_directories(dir.file("state"));
    ASSERT_EQ(::mkfifo(store.plan_path().c_str(), 0600), 0);
    std::filesystem::create_symlink("/dev/zero", store.progress_path());
    const auto started = std::chrono::steady_clock::now();
    const auto loaded = store.load();
    EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(2));
    EXPECT_FALSE(loaded.plan_text);
    ASSERT_EQ(loaded.problems.size(), 2u);
    EXPECT_NE(loaded.problems[0].find("not a regular file (a FIFO); set aside"), std::string::npos);
    EXPECT_NE(loaded.problems[1].find("not a regular file (a character device); set aside"),
              std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(store.plan_path())));
}

}  // namespace
}  // namespace airseg::flightplan
