#pragma once
// Turning what the StateStore kept into a running stream again, in one place: reload the plan text, rebuild
// the expander at the first unreached waypoint, and say what to tell the feeder.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "services/flightplan/expander.hpp"
#include "services/flightplan/persistence.hpp"
#include "services/flightplan/plan_loader.hpp"

namespace airseg::flightplan {

struct ResumedPlan {
    std::shared_ptr<const Plan> plan;
    std::string plan_text;
    std::string digest;                // hex64(fnv1a64(plan_text)), for SavedProgress
    std::unique_ptr<Expander> stream;  // positioned at the first unreached waypoint; null when done
    SavedProgress progress;            // what was saved (state none/running/paused/done)
};

struct ResumeResult {
    std::optional<ResumedPlan> resumed;  // empty: nothing to resume (see problems)
    std::vector<std::string> problems;   // everything worth logging, including the store's own findings
    /// The stored plan passed its checksum but no longer loads: its files are to be set aside
    /// (StateStore::set_aside_plan), so that the next start does not meet it again.
    bool set_aside = false;
};

/// Rebuilds the stream of a stored plan. A stored plan without progress starts from its beginning. Feed
/// the result to WindowFeeder::restore_plan(stream, progress.waypoints_reached) (after pause() when the
/// saved state is paused); a done plan has no stream.
ResumeResult resume_from(StoredState stored, const LoadOptions& options = {});

}  // namespace airseg::flightplan
