#pragma once
// YAML flight plan loader (format: docs/flight-plan.md). Every problem of a plan is reported at once, each
// located as file:line:col plus the element path; a plan with any error is not returned, so a rejected
// plan can change nothing downstream.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "services/flightplan/diagnostic.hpp"
#include "services/flightplan/plan.hpp"

namespace airseg::flightplan {

inline constexpr std::size_t kMaxPlanTextBytes = 16u << 20;

struct LoadOptions {
    /// Legs checked against no-fly zones at load time, per entry point (main list, each detached block).
    /// Finite plans below this size are checked completely; see docs/flight-plan.md for infinite ones.
    std::uint64_t leg_check_limit = 4'000'000;
    /// Refuse plans whose finite element lists expand to more waypoints than this.
    std::uint64_t max_finite_waypoints = 100'000'000;
    /// Refuse plans with more elements than this (YAML aliases can describe millions in a few bytes).
    std::size_t max_elements = 50'000;
    /// The most line-edge crossings (scan lines x polygon vertices, all scans of a plan together) laying out
    /// a plan's scans may take, on the service's strand: 0.27 s for 36,000,000 on the 2-core development
    /// machine; as much as the largest single scan took before (10,000,000 lines of 4 edges), now for the
    /// whole plan.
    std::uint64_t max_scan_work = 40'000'000;
    /// The profile of a plan without `vehicle` (flightplan.vehicle), and the base a plan's `vehicle` fields
    /// without `type` refine.
    VehicleProfile default_vehicle;
    /// A text's main list longer than this is read in batches of this many items (list_splice.hpp), which
    /// bounds yaml-cpp's per-item memory; 0 never splits it. Any value loads the same plan and diagnostics.
    std::size_t splice_batch_items = 256;
};

/// How a document was read, cheapest first; each later way is taken when the one before cannot be. All give
/// the same plan and diagnostics.
enum class PlanReading : unsigned char {
    Spliced,   // the main list cut out and read in batches (a text whose layout allows it)
    Streamed,  // element lists read one item at a time (plan_stream.hpp)
    Whole,     // the document as one tree
};

struct LoadResult {
    std::shared_ptr<const Plan> plan;  // null when errors is not empty
    std::vector<Diagnostic> errors;
    PlanReading reading = PlanReading::Whole;
    bool ok() const { return plan != nullptr; }
};

LoadResult load_plan_text(std::string_view text, const std::string& source_name,
                          const LoadOptions& options = {});
LoadResult load_plan_file(const std::string& path, const LoadOptions& options = {});

}  // namespace airseg::flightplan
