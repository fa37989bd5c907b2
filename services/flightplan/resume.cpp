#include "services/flightplan/resume.hpp"

namespace airseg::flightplan {

ResumeResult resume_from(StoredState stored, const LoadOptions& options) {
    ResumeResult out;
    out.problems = std::move(stored.problems);
    if (!stored.plan_text) {
        return out;
    }
    auto loaded = load_plan_text(*stored.plan_text, stored.plan_source, options);
    if (!loaded.ok()) {
        // The text passed its checksum, so it was accepted once: the loader or its options changed since.
        out.problems.push_back("stored plan no longer loads: " + loaded.errors.front().to_string() +
                               "; set aside");
        out.set_aside = true;
        return out;
    }
    ResumedPlan r;
    r.plan = loaded.plan;
    r.plan_text = std::move(*stored.plan_text);
    r.digest = hex64(fnv1a64(r.plan_text));
    if (stored.progress) {
        r.progress = *stored.progress;
    } else {
        r.progress.plan_digest = r.digest;
        r.progress.state = PlanState::Running;
    }
    if (r.progress.state == PlanState::Interrupted) {
        r.progress.state = PlanState::Paused;  // taken by hand or stopped by the board: the operator decides
    }
    if (r.progress.state != PlanState::Done && r.progress.state != PlanState::None &&
        r.progress.state != PlanState::Failed) {
        auto stream = std::make_unique<Expander>(r.plan);
        if (!stream->restore(r.progress.origin, r.progress.next_index)) {
            out.problems.push_back("saved position " + std::to_string(r.progress.next_index) +
                                   " is past the end of the plan; the plan is done");
            r.progress.state = PlanState::Done;
        } else {
            r.stream = std::move(stream);
        }
    }
    out.resumed = std::move(r);
    return out;
}

}  // namespace airseg::flightplan
