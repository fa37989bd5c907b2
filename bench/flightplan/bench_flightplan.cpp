// Flight plan benchmarks: expansion rate and memory of a 1,000,000-waypoint scan, seek cost, plan load
// (with no-fly validation), the memory of loading a plan written as an explicit list of waypoints and of
// appending to one (plan.append's merge), and the rolling-window feeder's cost per reached waypoint.
//
// Memory is measured with a counting allocator (this binary replaces global operator new/delete): the
// "peak_heap_bytes" counter is the largest heap growth while the stream is expanded, i.e. what the
// expansion itself allocates on top of the loaded plan. "maxrss_delta_kib" is getrusage's view of the
// same run (page granularity, process-wide).
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <sys/resource.h>

#include <unistd.h>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <random>
#include <string>

#include "services/flightplan/expander.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "services/flightplan/plan_merge.hpp"
#include "services/flightplan/window_feeder.hpp"

namespace {
std::atomic<std::int64_t> g_live{0};
std::atomic<std::int64_t> g_peak{0};

void note_alloc(void* p) {
    if (p == nullptr) {
        return;
    }
    const auto now = g_live.fetch_add(static_cast<std::int64_t>(malloc_usable_size(p))) +
                     static_cast<std::int64_t>(malloc_usable_size(p));
    auto peak = g_peak.load();
    while (now > peak && !g_peak.compare_exchange_weak(peak, now)) {
    }
}
}  // namespace

void* operator new(std::size_t n) {
    void* p = std::malloc(n == 0 ? 1 : n);
    if (p == nullptr) {
        throw std::bad_alloc();
    }
    note_alloc(p);
    return p;
}
void operator delete(void* p) noexcept {
    if (p == nullptr) {
        return;
    }
    g_live.fetch_sub(static_cast<std::int64_t>(malloc_usable_size(p)));
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    operator delete(p);
}

namespace airseg::flightplan {
namespace {

// 4.0 km x 4.0 km, lines 4 m apart, a waypoint every 4 m: 1000 lines x 1001 points = 1,001,000 waypoints.
const char* const kMillionScan = R"(plan:
  name: million
  vehicle: {type: rover}
  no_fly:
    - name: tower
      buffer: 10
      polygon: [[41.05, 2.05], [41.051, 2.05], [41.051, 2.051], [41.05, 2.051]]
  elements:
    - scan: {rectangle: {sw: [41.0, 2.0], ne: [41.036, 2.0477]}, spacing: 4, step: 4, heading: 0}
)";

std::shared_ptr<const Plan> million_plan() {
    static std::shared_ptr<const Plan> plan = [] {
        auto r = load_plan_text(kMillionScan, "million.yaml");
        if (!r.ok()) {
            std::abort();
        }
        return r.plan;
    }();
    return plan;
}

long maxrss_kib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss;
}

void BM_ExpandMillionWaypointScan(benchmark::State& state) {
    auto plan = million_plan();
    std::int64_t peak_growth = 0;
    std::uint64_t produced = 0;
    const long rss_before = maxrss_kib();
    for (auto _ : state) {
        const auto base = g_live.load();
        g_peak.store(base);
        Expander e(plan);
        std::uint64_t n = 0;
        while (auto w = e.next()) {
            benchmark::DoNotOptimize(w->position.lat);
            ++n;
        }
        produced = n;
        peak_growth = std::max(peak_growth, g_peak.load() - base);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(produced) * state.iterations());
    state.counters["waypoints"] = static_cast<double>(produced);
    state.counters["peak_heap_bytes"] = static_cast<double>(peak_growth);
    state.counters["maxrss_delta_kib"] = static_cast<double>(maxrss_kib() - rss_before);
}
BENCHMARK(BM_ExpandMillionWaypointScan)->Unit(benchmark::kMillisecond);

void BM_SeekInMillionWaypointScan(benchmark::State& state) {
    auto plan = million_plan();
    Expander e(plan);
    std::mt19937_64 rng(1);
    const std::uint64_t total = plan->count(plan->main_list).value();
    for (auto _ : state) {
        const std::uint64_t target = rng() % total;
        benchmark::DoNotOptimize(e.seek(target));
        benchmark::DoNotOptimize(e.next());
    }
}
BENCHMARK(BM_SeekInMillionWaypointScan)->Unit(benchmark::kMicrosecond);

void BM_LoadAndValidateMillionWaypointPlan(benchmark::State& state) {
    for (auto _ : state) {
        auto r = load_plan_text(kMillionScan, "million.yaml");
        benchmark::DoNotOptimize(r.plan);
    }
}
BENCHMARK(BM_LoadAndValidateMillionWaypointPlan)->Unit(benchmark::kMillisecond);

// A plan written as an explicit list: `count` waypoints, one per line, about 50 bytes each (coordinates to
// 1e-7 degrees, as a ground station writes them), or 38 (`short_lines`: one decimal, the shortest usual
// line).
std::string explicit_list_plan(int count, bool short_lines = false) {
    std::string text = "plan:\n  name: explicit\n  vehicle: {type: rover}\n  elements:\n";
    char line[96];
    for (int i = 0; i < count; ++i) {
        const double lat = 41.0 + (i / 200) * 5e-5;
        const double lon = 2.0 + (i % 200) * 5e-5;
        std::snprintf(line, sizeof line,
                      short_lines ? "    - waypoint: {lat: %.1f, lon: %.1f}\n"
                                  : "    - waypoint: {lat: %.7f, lon: %.7f}\n",
                      lat, lon);
        text += line;
    }
    return text;
}

// Heap kept per element after the load, and the heap peak while loading relative to the file's size. Two
// ways in: load_plan_file (reads the file itself; its peak includes whatever it buffers of the text) and
// load_plan_text (the daemon's way: the text is already in memory, held by the caller, and not counted).
void BM_LoadExplicitList(benchmark::State& state, bool from_file, bool short_lines) {
    const int count = static_cast<int>(state.range(0));
    const std::string text = explicit_list_plan(count, short_lines);
    const auto file = std::filesystem::temp_directory_path() /
                      ("airseg-bench-explicit-" + std::to_string(::getpid()) + ".yaml");
    if (from_file) {
        std::ofstream(file, std::ios::binary) << text;
    }
    LoadOptions options;
    options.max_elements = 1'000'000;
    std::int64_t kept = 0, peak = 0;
    std::size_t elements = 0;
    PlanReading reading = PlanReading::Whole;
    for (auto _ : state) {
        const auto base = g_live.load();
        g_peak.store(base);
        auto r = from_file ? load_plan_file(file.string(), options)
                           : load_plan_text(text, "explicit.yaml", options);
        if (!r.ok()) {
            std::abort();
        }
        peak = g_peak.load() - base;
        kept = g_live.load() - base;
        elements = r.plan->children(r.plan->main_list).size();
        reading = r.reading;
        benchmark::DoNotOptimize(r.plan);
    }
    if (from_file) {
        std::filesystem::remove(file);
    }
    state.counters["elements"] = static_cast<double>(elements);
    state.counters["file_bytes"] = static_cast<double>(text.size());
    state.counters["kept_bytes_per_element"] = static_cast<double>(kept) / static_cast<double>(elements);
    state.counters["peak_heap_bytes"] = static_cast<double>(peak);
    state.counters["peak_over_file"] = static_cast<double>(peak) / static_cast<double>(text.size());
    state.counters["spliced"] = reading == PlanReading::Spliced ? 1.0 : 0.0;  // the main list read in batches
}
BENCHMARK_CAPTURE(BM_LoadExplicitList, text, false, false)
    ->Arg(4'000)
    ->Arg(40'000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadExplicitList, text_short_lines, false, true)
    ->Arg(4'000)
    ->Arg(40'000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadExplicitList, file, true, false)
    ->Arg(4'000)
    ->Arg(40'000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadExplicitList, file_short_lines, true, true)
    ->Arg(4'000)
    ->Arg(40'000)
    ->Unit(benchmark::kMillisecond);

// plan.append: `running` explicit-list elements, then `appended` more. The merge streams the running text
// (parser events to an emitter) and copies the appended items in, so its peak is about the merged text plus
// the parser's; peak_over_texts relates it to both texts, peak_over_file to the running one as before.
void BM_AppendToExplicitList(benchmark::State& state) {
    const std::string running = explicit_list_plan(static_cast<int>(state.range(0)));
    const std::string appended = explicit_list_plan(static_cast<int>(state.range(1)));
    std::int64_t peak = 0;
    bool whole_tree = false;
    for (auto _ : state) {
        const auto base = g_live.load();
        g_peak.store(base);
        auto merged = append_plan_text(running, appended);
        if (!merged.text) {
            std::abort();
        }
        peak = g_peak.load() - base;
        whole_tree = merged.whole_tree;
        benchmark::DoNotOptimize(merged.text);
    }
    const auto texts = static_cast<double>(running.size() + appended.size());
    state.counters["file_bytes"] = static_cast<double>(running.size());
    state.counters["peak_heap_bytes"] = static_cast<double>(peak);
    state.counters["peak_over_file"] = static_cast<double>(peak) / static_cast<double>(running.size());
    state.counters["peak_over_texts"] = static_cast<double>(peak) / texts;
    state.counters["whole_tree"] = whole_tree ? 1.0 : 0.0;
}
BENCHMARK(BM_AppendToExplicitList)
    ->Args({40'000, 10})
    ->Args({10, 40'000})
    ->Args({20'000, 20'000})
    ->Unit(benchmark::kMillisecond);

// The feeder's own work per reached waypoint: reached report, refill, one partial write, result.
void BM_FeederPerReachedWaypoint(benchmark::State& state) {
    auto plan = million_plan();
    WindowFeeder feeder;
    TimePoint now{};
    feeder.replace_plan({std::make_unique<Expander>(plan), "million"}, now);
    auto settle = [&] {
        while (auto r = feeder.poll_request(now)) {
            feeder.on_request_result(r->id, autopilot::RequestResult::Ok, now);
        }
        while (feeder.poll_event()) {
        }
    };
    settle();
    std::uint16_t slot = 1;
    for (auto _ : state) {
        feeder.on_reached(slot, now);
        settle();
        slot = slot >= feeder.config().window ? 1 : slot + 1;
        now += seconds(1);
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FeederPerReachedWaypoint);

}  // namespace
}  // namespace airseg::flightplan

BENCHMARK_MAIN();
