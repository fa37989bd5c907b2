// Fuzzes the flight plan loader with arbitrary YAML text, then expands what it accepts. For any text: the
// loader accepts it or every diagnostic names a message (and a line when it has one, within the text); the
// main list read in batches of one item (list_splice.hpp) gives the same diagnostics and plan as read
// unsplit; an accepted plan expands deterministically (two expanders give the same first waypoints) to
// coordinates in range, and expansion never crashes.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "services/flightplan/expander.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "tests/fuzz/require.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace airseg::flightplan;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    LoadOptions options;
    // Small limits keep one input fast; the limits' own errors are exercised too.
    options.leg_check_limit = 20'000;
    options.max_finite_waypoints = 200'000;
    options.max_elements = 2'000;
    options.splice_batch_items = 1;
    const LoadResult result = load_plan_text(text, "fuzz.yaml", options);
    options.splice_batch_items = 0;
    const LoadResult unsplit = load_plan_text(text, "fuzz.yaml", options);
    require(result.errors.size() == unsplit.errors.size());
    for (std::size_t i = 0; i < result.errors.size(); ++i) {
        require(result.errors[i].to_string() == unsplit.errors[i].to_string());
    }
    require(result.ok() == unsplit.ok());
    if (result.ok()) {
        const auto& a = result.plan->nodes;
        const auto& b = unsplit.plan->nodes;
        require(a.size() == b.size() && result.plan->extras.size() == unsplit.plan->extras.size());
        for (std::size_t i = 0; i < a.size(); ++i) {
            require(a[i].kind == b[i].kind && a[i].parent == b[i].parent &&
                    a[i].mark.line == b[i].mark.line && a[i].mark.col == b[i].mark.col &&
                    a[i].geo.lat == b[i].geo.lat && a[i].geo.lon == b[i].geo.lon);
        }
    }
    if (!result.ok()) {
        require(!result.errors.empty());
        const auto lines = static_cast<int>(std::count(text.begin(), text.end(), '\n')) + 1;
        for (const auto& d : result.errors) {
            require(!d.message.empty());
            require(d.line >= 0 && d.line <= lines + 1);
        }
        return 0;
    }
    Expander first(result.plan);
    Expander second(result.plan);
    for (int i = 0; i < 500; ++i) {
        const auto a = first.next();
        const auto b = second.next();
        require(a.has_value() == b.has_value());
        if (!a) {
            break;
        }
        require(a->index == b->index && a->has_position == b->has_position);
        if (a->has_position) {
            const auto& p = a->position;
            require(p.lat == b->position.lat && p.lon == b->position.lon);
            require(std::isfinite(p.lat) && std::isfinite(p.lon));
            require(p.lat >= -90.0 && p.lat <= 90.0 && p.lon >= -180.0 && p.lon <= 180.0);
        }
    }
    return 0;
}
