// StateStore in a temp directory: round trip, atomic overwrite, corrupt files set aside (truncated,
// garbage, altered, another plan's progress), and a restart that resumes at the first unreached waypoint.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <random>

#include "services/flightplan/expander.hpp"
#include "services/flightplan/persistence.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "tests/unit/flightplan/sim_autopilot.hpp"

namespace airseg::flightplan {
namespace {

namespace fs = std::filesystem;

class TempDir {
  public:
    TempDir() {
        std::string tmpl = (fs::temp_directory_path() / "airseg-fp-XXXXXX").string();
        path_ = ::mkdtemp(tmpl.data());
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    const fs::path& path() const { return path_; }

  private:
    fs::path path_;
};

std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

void write(const fs::path& p, const std::string& data) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out << data;
}

const std::string kPlanText = "plan:\n  name: p\n  elements:\n    - waypoint: {lat: 41.0, lon: 2.0}\n";

SavedProgress sample_progress() {
    SavedProgress p;
    p.plan_digest = hex64(fnv1a64(kPlanText));
    p.state = PlanState::Paused;
    p.origin = {7, 120};
    p.next_index = 345;
    p.waypoints_reached = 300;
    return p;
}

TEST(FlightplanPersistence, RoundTripAndOverwriteLeaveNoTempFiles) {
    TempDir dir;
    StateStore store(dir.path() / "state");
    ASSERT_FALSE(store.save_plan(kPlanText, "plans/p.yaml").has_value());
    SavedProgress p = sample_progress();
    for (std::uint64_t i = 0; i < 5; ++i) {
        p.next_index = 345 + i;
        ASSERT_FALSE(store.save_progress(p).has_value());
    }
    const auto loaded = store.load();
    EXPECT_TRUE(loaded.problems.empty());
    ASSERT_TRUE(loaded.plan_text.has_value());
    EXPECT_EQ(*loaded.plan_text, kPlanText);
    EXPECT_EQ(loaded.plan_source, "plans/p.yaml");
    ASSERT_TRUE(loaded.progress.has_value());
    EXPECT_EQ(*loaded.progress, p);
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir.path() / "state")) {
        EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos);
        ++files;
    }
    EXPECT_EQ(files, 2);
}

TEST(FlightplanPersistence, TruncatedProgressIsSetAsideEveryTime) {
    TempDir dir;
    StateStore store(dir.path());
    ASSERT_FALSE(store.save_plan(kPlanText, "p.yaml"));
    for (int round = 1; round <= 2; ++round) {
        ASSERT_FALSE(store.save_progress(sample_progress()));
        const std::string full = read(store.progress_path());
        write(store.progress_path(), full.substr(0, full.size() / 2));
        const auto loaded = store.load();
        EXPECT_FALSE(loaded.progress.has_value());
        ASSERT_TRUE(loaded.plan_text.has_value());
        ASSERT_EQ(loaded.problems.size(), 1u);
        EXPECT_NE(loaded.problems[0].find("set aside"), std::string::npos);
        EXPECT_TRUE(fs::exists(store.progress_path().string() + ".corrupt-" + std::to_string(round)));
        EXPECT_FALSE(fs::exists(store.progress_path()));
    }
}

TEST(FlightplanPersistence, GarbageAndEveryTruncationNeverCrash) {
    TempDir dir;
    StateStore store(dir.path());
    ASSERT_FALSE(store.save_plan(kPlanText, "p.yaml"));
    ASSERT_FALSE(store.save_progress(sample_progress()));
    const std::string good_plan = read(store.plan_path());
    const std::string good_progress = read(store.progress_path());
    std::mt19937 rng(42);
    // Every cut short of the final newline (without it the content is still complete and valid).
    for (std::size_t cut = 0; cut + 1 < good_progress.size();
         cut += (cut < 20 || cut + 20 > good_progress.size()) ? 1 : 7) {
        write(store.plan_path(), good_plan);
        write(store.progress_path(), good_progress.substr(0, cut));
        const auto loaded = store.load();
        EXPECT_FALSE(loaded.progress.has_value()) << cut;
        EXPECT_TRUE(loaded.plan_text.has_value());
    }
    for (int k = 0; k < 20; ++k) {
        std::string junk(std::uniform_int_distribution<std::size_t>(0, 6000)(rng), '\0');
        for (char& c : junk) {
            c = static_cast<char>(rng());
        }
        write(store.plan_path(), junk);
        write(store.progress_path(), junk);
        const auto loaded = store.load();
        EXPECT_FALSE(loaded.plan_text.has_value());
        EXPECT_FALSE(loaded.progress.has_value());
        EXPECT_EQ(loaded.problems.size(), 2u);
    }
}

TEST(FlightplanPersistence, AlteredPlanAndForeignProgressAreRejected) {
    TempDir dir;
    StateStore store(dir.path());
    ASSERT_FALSE(store.save_plan(kPlanText, "p.yaml"));
    SavedProgress foreign = sample_progress();
    foreign.plan_digest = hex64(fnv1a64("another plan"));
    ASSERT_FALSE(store.save_progress(foreign));
    auto loaded = store.load();
    EXPECT_TRUE(loaded.plan_text.has_value());
    EXPECT_FALSE(loaded.progress.has_value());
    ASSERT_EQ(loaded.problems.size(), 1u);
    EXPECT_NE(loaded.problems[0].find("another plan"), std::string::npos);

    std::string altered = read(store.plan_path());
    altered[altered.size() - 3] ^= 0x20;
    write(store.plan_path(), altered);
    loaded = store.load();
    EXPECT_FALSE(loaded.plan_text.has_value());
    EXPECT_TRUE(fs::exists(store.plan_path().string() + ".corrupt-1"));
}

TEST(FlightplanPersistence, InterruptedWriteLeavesThePreviousStateIntact) {
    TempDir dir;
    StateStore store(dir.path());
    ASSERT_FALSE(store.save_plan(kPlanText, "p.yaml"));
    ASSERT_FALSE(store.save_progress(sample_progress()));
    // A crash between write and rename leaves only a temp file behind.
    write(store.progress_path().string() + ".tmp", "airseg-progress 1\nplan_dig");
    const auto loaded = store.load();
    ASSERT_TRUE(loaded.progress.has_value());
    EXPECT_EQ(*loaded.progress, sample_progress());
    EXPECT_FALSE(fs::exists(store.progress_path().string() + ".tmp"));
}

TEST(FlightplanPersistence, RestartResumesAtTheFirstUnreachedWaypoint) {
    TempDir dir;
    const std::string text = R"(plan:
  name: resume
  elements:
    - waypoint: {lat: 41.0, lon: 2.0}
    - repeat:
        name: laps
        count: 50
        elements:
          - scan: {rectangle: {sw: [41.0, 2.0], ne: [41.0004, 2.0004]}, spacing: 5}
)";
    auto loaded = load_plan_text(text, "resume.yaml");
    ASSERT_TRUE(loaded.ok()) << to_string(loaded.errors);
    std::vector<LatLon> expected;
    {
        Expander all(loaded.plan);
        while (auto w = all.next()) {
            expected.push_back(w->position);
        }
    }
    const std::string digest = hex64(fnv1a64(text));
    // Durability against power loss is fsync's business; this scenario is about kill -9, so skip the fsyncs.
    StateStore store(dir.path(), Durability::NoFsync);
    ASSERT_FALSE(store.save_plan(text, "resume.yaml"));

    // First life of the daemon: fly a while, saving progress after every step; then "kill -9".
    std::uint64_t reached_before = 0;
    test::SimAutopilot autopilot;
    {
        test::Harness h;
        h.feeder.replace_plan({std::make_unique<Expander>(loaded.plan), "resume"}, h.now);
        for (int i = 0; i < 61; ++i) {
            h.step();
            ASSERT_FALSE(store.save_progress(SavedProgress::from(h.feeder.progress(), digest)));
        }
        reached_before = h.reached.size();
        autopilot = h.ap;
    }
    // Second life: reload everything from disk.
    const auto state = store.load();
    ASSERT_TRUE(state.problems.empty());
    ASSERT_TRUE(state.plan_text && state.progress);
    EXPECT_EQ(state.progress->next_index, reached_before);
    EXPECT_EQ(state.progress->waypoints_reached, reached_before);
    auto plan = load_plan_text(*state.plan_text, state.plan_source);
    ASSERT_TRUE(plan.ok());
    auto stream = std::make_unique<Expander>(plan.plan);
    ASSERT_TRUE(stream->restore(state.progress->origin, state.progress->next_index));
    test::Harness h;
    h.ap = autopilot;  // the autopilot kept running its old mission meanwhile
    h.feeder.restore_plan({std::move(stream), "resume"}, state.progress->waypoints_reached, h.now);
    ASSERT_LT(h.run_until_done(20000), 20000);
    ASSERT_FALSE(h.reached.empty());
    EXPECT_EQ(h.reached.front(), reached_before);
    EXPECT_EQ(h.reached.back(), expected.size() - 1);
    EXPECT_EQ(h.feeder.progress().waypoints_reached, expected.size());
    // The vehicle drove every waypoint, the first unreached one right after the restart.
    const auto& visited = h.ap.visited();
    ASSERT_EQ(visited.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        ASSERT_EQ(visited[i], expected[i]) << i;
    }
}

}  // namespace
}  // namespace airseg::flightplan

#include "services/flightplan/resume.hpp"

namespace airseg::flightplan {
namespace {

TEST(FlightplanPersistence, ResumeFromStoredState) {
    TempDir dir;
    StateStore store(dir.path(), Durability::NoFsync);
    EXPECT_FALSE(resume_from(store.load()).resumed.has_value());  // empty store: nothing to resume

    const std::string text = R"(plan:
  name: r
  elements:
    - repeat: {count: 10, elements: [{waypoint: {lat: 41.0, lon: 2.0}}, {waypoint: {lat: 41.001, lon: 2.0}}]}
)";
    ASSERT_FALSE(store.save_plan(text, "r.yaml"));
    auto fresh = resume_from(store.load());
    ASSERT_TRUE(fresh.resumed.has_value());
    ASSERT_TRUE(fresh.resumed->stream);
    EXPECT_EQ(fresh.resumed->stream->next()->index, 0u);  // no progress yet: from the start

    SavedProgress p;
    p.plan_digest = fresh.resumed->digest;
    p.state = PlanState::Paused;
    p.next_index = 13;
    p.waypoints_reached = 13;
    ASSERT_FALSE(store.save_progress(p));
    auto paused = resume_from(store.load());
    ASSERT_TRUE(paused.resumed && paused.resumed->stream);
    EXPECT_EQ(paused.resumed->progress.state, PlanState::Paused);
    const auto w = paused.resumed->stream->next();
    ASSERT_TRUE(w);
    EXPECT_EQ(w->index, 13u);
    EXPECT_DOUBLE_EQ(w->position.lat, 41.001);

    p.state = PlanState::Running;
    p.next_index = 20;  // past the end
    ASSERT_FALSE(store.save_progress(p));
    auto past = resume_from(store.load());
    ASSERT_TRUE(past.resumed);
    EXPECT_FALSE(past.resumed->stream);
    EXPECT_EQ(past.resumed->progress.state, PlanState::Done);
    EXPECT_EQ(past.problems.size(), 1u);
}

}  // namespace
}  // namespace airseg::flightplan
