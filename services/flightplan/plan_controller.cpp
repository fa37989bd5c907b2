#include "services/flightplan/plan_controller.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "base/utf8.hpp"
#include "services/flightplan/home_stream.hpp"
#include "services/flightplan/plan_merge.hpp"

namespace airseg::flightplan {

namespace {

using Level = LogLine::Level;
using Status = CommandReply::Status;

// The top-level element index from an element path such as "plan.elements[12].scan".
std::uint32_t top_element_index(const std::string& path) {
    const auto open = path.find('[');
    const auto close = path.find(']', open);
    if (open == std::string::npos || close == std::string::npos) {
        return 0;
    }
    std::uint32_t n = 0;
    for (auto i = open + 1; i < close && path[i] >= '0' && path[i] <= '9'; ++i) {
        n = n * 10 + static_cast<std::uint32_t>(path[i] - '0');
    }
    return n;
}

Json optional_json(const std::optional<std::uint64_t>& v) {
    return v ? Json(*v) : Json(nullptr);
}

template <typename T>
std::optional<T> pop(std::deque<T>& q) {
    if (q.empty()) {
        return std::nullopt;
    }
    T out = std::move(q.front());
    q.pop_front();
    return out;
}

}  // namespace

PlanController::PlanController(PlanControllerConfig config)
    : config_(std::move(config)), feeder_(config_.feeder) {}

// ---- life cycle ----------------------------------------------------------------------------------------

void PlanController::start(TimePoint now) {
    running_ = true;
    pump(now);
    publish_status(true);
}

void PlanController::stop(const std::string& why) {
    running_ = false;
    fail_waiters(why);
}

void PlanController::resume(ResumeResult result, TimePoint now) {
    for (const auto& p : result.problems) {
        log(Level::Warn, p);
        problem_ = p;
    }
    if (!result.resumed) {
        return;
    }
    auto& r = *result.resumed;
    if (!r.stream) {
        log(Level::Info, fmt::format("stored plan '{}' was {}; nothing to resume", r.plan->name,
                                     to_string(r.progress.state)));
        return;
    }
    ActivePlan plan;
    plan.plan = r.plan;
    plan.text = std::move(r.plan_text);
    plan.source = r.plan->source_file;
    plan.digest = r.digest;
    plan.stream = r.stream.get();
    if (r.progress.state == PlanState::Paused) {
        feeder_.pause();
    }
    feeder_.restore_plan(PlanFeed{std::move(r.stream), r.plan->name}, r.progress.waypoints_reached, now);
    reactions_ = std::make_unique<ReactionMonitor>(ReactionSettings::from_plan(*plan.plan));
    tell_reactions_the_link(now);
    tell_reactions_the_telemetry(now);
    log(Level::Info, fmt::format("resuming plan '{}' ({}) at waypoint {}, {} reached{}", r.plan->name,
                                 plan.source, r.progress.next_index, r.progress.waypoints_reached,
                                 r.progress.state == PlanState::Paused ? ", paused" : ""));
    active_ = std::move(plan);
}

// ---- plans ---------------------------------------------------------------------------------------------

void PlanController::start_plan(ActivePlan plan, bool append, TimePoint now) {
    auto stream = std::make_unique<Expander>(plan.plan);
    Expander* raw = stream.get();
    if (append && active_ && active_->stream) {
        // The merged plan expands like the running one up to its end: continue from the same place.
        (void)raw->restore(active_->stream->origin(), active_->stream->position());  // probed by prepare_load
        feeder_.continue_with(PlanFeed{std::move(stream), plan.plan->name}, now);
    } else {
        feeder_.replace_plan(PlanFeed{std::move(stream), plan.plan->name}, now);
    }
    plan.stream = raw;
    reactions_ = std::make_unique<ReactionMonitor>(ReactionSettings::from_plan(*plan.plan));
    tell_reactions_the_link(now);
    tell_reactions_the_telemetry(now);
    active_ = std::move(plan);
    returning_home_ = false;
    problem_.clear();
    last_saved_.reset();
    last_written_.reset();
    save_progress();
}

// The link's state comes as a change (LinkState): a new plan's reactions start from the one last heard.
void PlanController::tell_reactions_the_link(TimePoint now) {
    if (groundlink_seen_up_ && reactions_) {
        reactions_->on_link(groundlink_up_, now);
    }
}

// Telemetry comes only when it changes (the bus drops a value equal to the last): a new plan's reactions
// start from the battery and position last heard, or a plan loaded on a low battery at rest would never
// react.
void PlanController::tell_reactions_the_telemetry(TimePoint now) {
    if (!reactions_) {
        return;
    }
    if (last_battery_) {
        reactions_->on_battery(*last_battery_, now);
    }
    if (last_position_) {
        reactions_->on_position(*last_position_, now);
    }
}

void PlanController::save_progress() {
    if (!config_.keeps_progress || !active_ || returning_home_) {
        return;
    }
    const FeederProgress p = feeder_.progress();
    if (p.state == PlanState::None) {
        return;
    }
    SavedProgress s = SavedProgress::from(p, active_->digest);
    if (p.state != PlanState::Done && !p.resume_index) {
        return;  // between states (nothing queued yet): the last saved point still holds
    }
    if (last_saved_ && *last_saved_ == s) {
        return;
    }
    // Taken as saved until the store says otherwise (on_saved): the same point is not written twice.
    last_saved_ = s;
    saves_.push_back(ProgressSave{std::move(s), true});
}

void PlanController::on_saved(const ProgressSave& save, const std::optional<std::string>& error) {
    if (!error) {
        last_saved_ = last_written_ = save.progress;
        return;
    }
    if (!save.report_failure) {
        return;
    }
    if (last_saved_ && *last_saved_ == save.progress) {
        last_saved_ = last_written_;  // not kept: the next input tries this point again
    }
    if (problem_ != *error) {
        log(Level::Error, "cannot save progress: " + *error);
    }
    problem_ = *error;
    publish_status(false);
}

bool PlanController::return_home(TimePoint now) {
    std::optional<LatLon> home;
    if (active_ && active_->plan->home) {
        home = *active_->plan->home;
    } else if (autopilot_home_) {
        home = LatLon{autopilot_home_->lat, autopilot_home_->lon};
    }
    if (!home || !active_) {
        return false;
    }
    const auto& v = active_->plan->vehicle;
    // The plan's progress stays saved where it was interrupted (paused), so a restart does not drive on.
    if (config_.keeps_progress && last_written_) {
        SavedProgress paused = *last_written_;
        paused.state = PlanState::Paused;
        saves_.push_back(ProgressSave{std::move(paused), false});
    }
    feeder_.replace_plan(
        PlanFeed{std::make_unique<HomeStream>(*home, v.commanded_cruise_speed(), v.arrival_radius),
                 active_->plan->name + " (return home)"},
        now);
    active_->stream = nullptr;
    returning_home_ = true;
    return true;
}

void PlanController::carry_out(const ReactionTrigger& t, TimePoint now) {
    const std::string cause = to_string(t.cause);
    std::string what;
    switch (t.reaction.action) {
        case ReactionAction::Hold:
            feeder_.pause();
            what = "hold";
            break;
        case ReactionAction::Continue:
            what = "continue";
            break;
        case ReactionAction::GotoBlock:
            what = feeder_.jump_to(t.reaction.target, now) ? "goto " + t.reaction.target
                                                           : "goto " + t.reaction.target + " failed; hold";
            if (what.ends_with("hold")) {
                feeder_.pause();
            }
            break;
        case ReactionAction::ReturnHome:
            what = return_home(now) ? "return home" : "return home impossible (no home known); hold";
            if (what.ends_with("hold")) {
                feeder_.pause();
            }
            break;
    }
    if (t.cause == ReactionTrigger::Cause::LinkRecovered) {
        what = "nothing (the link-loss reaction stays in effect)";
    }
    last_reaction_ = cause + ": " + what + (t.detail.empty() ? "" : " (" + t.detail + ")");
    log(Level::Warn, "reaction " + last_reaction_);
    outputs_.emplace_back(t);
}

// ---- autopilot side ------------------------------------------------------------------------------------

void PlanController::on_autopilot_status(const autopilot::AutopilotStatus& s, TimePoint now) {
    if (s.ready == autopilot_ready_) {
        return;
    }
    autopilot_ready_ = s.ready;
    const std::pair<unsigned, unsigned> counts{s.reconnects, s.reboots};
    if (!autopilot_ready_) {
        // Lost: the window is kept. A board that only went silent drives on, and the waypoints it reports
        // reached meanwhile still count; a reboot (its own event) or a reopened port makes it unknown.
        answer_waiters_without_autopilot("the autopilot is not ready");
        pump(now);
        return;
    }
    const bool same_board = ready_counts_ && *ready_counts_ == counts;
    ready_counts_ = counts;
    if (same_board) {
        pump(now);  // back, neither rebooted nor reconnected: it still holds the window
        return;
    }
    // Connected afresh: what the autopilot holds is unknown; the window is uploaded again.
    on_rebooted(now);
}

void PlanController::on_telemetry(const autopilot::Telemetry& t, TimePoint now) {
    if (t.home) {
        autopilot_home_ = t.home;
    }
    last_battery_ = t.battery_remaining;
    if (t.position) {
        last_position_ = LatLon{t.position->lat, t.position->lon};
    }
    if (!reactions_) {
        return;
    }
    tell_reactions_the_telemetry(now);
    pump(now);
}

void PlanController::on_reached(std::uint32_t seq, TimePoint now) {
    feeder_.on_reached(seq, now);
    pump(now);
}

void PlanController::on_current(std::uint32_t seq, TimePoint now) {
    feeder_.on_current(seq, now);
    pump(now);
}

void PlanController::on_item_stored(std::uint16_t slot, const autopilot::MissionItem& item, TimePoint now) {
    feeder_.on_item_stored(slot, item);
    pump(now);
}

void PlanController::on_rebooted(TimePoint now) {
    feeder_.on_autopilot_rebooted(now);
    in_flight_.clear();
    pump(now);
}

void PlanController::on_mode_changed(const autopilot::ModeChanged& m, TimePoint now) {
    feeder_.on_mode(m.to, m.cause, now);
    pump(now);
}

void PlanController::on_request_done(std::uint32_t id, const autopilot::RequestDone& done, TimePoint now) {
    const auto it = in_flight_.find(id);
    if (it == in_flight_.end()) {
        return;  // forgotten after a reconnect
    }
    const std::uint32_t feeder_id = it->second.feeder_id;
    log(Level::Debug,
        fmt::format("#{} {} in {} ms", feeder_id, autopilot::to_string(done.result),
                    std::chrono::duration_cast<std::chrono::milliseconds>(now - it->second.sent).count()));
    in_flight_.erase(it);
    if (done.result == autopilot::RequestResult::Ok) {
        fault_.reset();
    } else {
        last_failure_ = std::string(autopilot::to_string(done.kind)) + ": " +
                        autopilot::to_string(done.result) +
                        (done.detail.empty() ? "" : " (" + done.detail + ")");
    }
    if (done.stop_ends_mission) {
        feeder_.set_stop_ends_mission(*done.stop_ends_mission);
    }
    feeder_.on_request_result(feeder_id, done.result, now, last_failure_);
    pump(now);
}

void PlanController::on_link(bool up, TimePoint now) {
    // Link loss means losing a link that was there: a vehicle started without a ground station does not
    // react to its absence.
    groundlink_seen_up_ = groundlink_seen_up_ || up;
    groundlink_up_ = up;
    if (groundlink_seen_up_ && reactions_) {
        reactions_->on_link(up, now);
        pump(now);
    }
}

void PlanController::send(const FeederRequest& request, TimePoint now) {
    autopilot::AutopilotRequest r;
    const std::uint32_t id = next_call_id_++;
    std::visit([&](const auto& op) { r.op = op; }, request.op);
    std::ostringstream o;
    o << request;
    log(Level::Debug, o.str());
    in_flight_[id] = InFlight{request.id, now};
    outputs_.emplace_back(AutopilotCall{id, std::move(r)});
}

void PlanController::pump(TimePoint now) {
    if (!running_) {
        return;
    }
    if (feeder_.poll_timeout() <= now) {
        feeder_.handle_timeout(now);
    }
    if (reactions_) {
        if (reactions_->poll_timeout() <= now) {
            reactions_->handle_timeout(now);
        }
        while (auto t = reactions_->poll_trigger()) {
            carry_out(*t, now);
        }
    }
    if (autopilot_ready_) {
        while (auto r = feeder_.poll_request(now)) {
            send(*r, now);
        }
    }
    while (auto e = feeder_.poll_event()) {
        handle_event(*e);
    }
    save_progress();
    answer_waiters(now);
    publish_status(false);
}

void PlanController::handle_event(const FeederEvent& e) {
    switch (e.kind) {
        case FeederEvent::Kind::WaypointReached:
            log(Level::Debug, fmt::format("waypoint {} reached ({})", e.plan_index, e.element_path));
            break;
        case FeederEvent::Kind::ElementStarted:
        case FeederEvent::Kind::ElementFinished:
        case FeederEvent::Kind::HoldStarted:
        case FeederEvent::Kind::HoldEnded:
            log(Level::Info, fmt::format("{} {}", to_string(e.kind), e.element_path));
            break;
        case FeederEvent::Kind::PlanDone:
            log(Level::Info, fmt::format("plan '{}' done", feeder_.progress().plan_name));
            break;
        case FeederEvent::Kind::PlanBlocked:
            log(Level::Error, "plan stopped: " + e.detail);
            problem_ = e.detail;
            break;
        case FeederEvent::Kind::RequestFailed:
            fault_ = last_failure_.empty() ? e.detail : last_failure_;
            log(Level::Error, fmt::format("autopilot request failed after retries: {}; holding", *fault_));
            fail_waiters("the autopilot did not confirm: " + *fault_);
            break;
        case FeederEvent::Kind::WindowStarved:
            log(Level::Warn,
                fmt::format("window starved at waypoint {}: holding until it is written", e.plan_index));
            break;
        case FeederEvent::Kind::HeldAtFrontier:
            log(Level::Warn,
                fmt::format("waiting for waypoint {} to reach the autopilot: {}", e.plan_index, e.detail));
            break;
        case FeederEvent::Kind::Interrupted:
            log(Level::Warn, fmt::format("plan interrupted at waypoint {}: {}", e.plan_index, e.detail));
            break;
        case FeederEvent::Kind::Continued:
            log(Level::Info, fmt::format("plan continues at waypoint {} after: {}", e.plan_index, e.detail));
            break;
        case FeederEvent::Kind::PlanFailed:
            log(Level::Error, "plan failed, the vehicle is held: " + e.detail);
            problem_ = "the autopilot refused the plan: " + e.detail;
            fail_waiters(problem_);
            break;
    }
    outputs_.emplace_back(e);
}

// ---- commands ------------------------------------------------------------------------------------------

void PlanController::wait_for_autopilot(CommandId id, std::string what, TimePoint now) {
    waiters_.push_back(Waiter{id, std::move(what), now + config_.command_timeout});
    pump(now);
}

void PlanController::answer_waiters(TimePoint now) {
    if (waiters_.empty()) {
        return;
    }
    if (!autopilot_ready_) {
        answer_waiters_without_autopilot("the autopilot is not ready");
        return;
    }
    if (fault_) {
        fail_waiters("the autopilot did not confirm: " + *fault_);
        return;
    }
    // Idle: nothing in flight and nothing more to ask: everything the commands needed is confirmed.
    if (in_flight_.empty()) {
        auto done = std::move(waiters_);
        waiters_.clear();
        const Json progress = progress_json();
        for (auto& w : done) {
            reply(w.id, Status::Ok, {}, progress);
        }
        return;
    }
    std::vector<Waiter> keep;
    for (auto& w : waiters_) {
        if (now >= w.deadline) {
            reply(w.id, Status::Failed,
                  w.what + ": the autopilot did not confirm in time" +
                      (last_failure_.empty() ? "" : " (last failure: " + last_failure_ + ")"));
        } else {
            keep.push_back(std::move(w));
        }
    }
    waiters_ = std::move(keep);
}

void PlanController::fail_waiters(const std::string& why) {
    auto failed = std::move(waiters_);
    waiters_.clear();
    for (auto& w : failed) {
        reply(w.id, Status::Failed, w.what + ": " + why);
    }
}

void PlanController::answer_waiters_without_autopilot(const std::string& why) {
    // A plan loaded or appended is the plan from now on, kept in the state directory, and the board gets it
    // when it is back: the command is done ("kept"). A skip, pause or resume is kept as well, but it is done
    // only when the board does it, and a board that merely went silent may still be driving: the operator is
    // told it is not done yet.
    auto waiting = std::move(waiters_);
    waiters_.clear();
    for (auto& w : waiting) {
        if (w.what == "plan.load" || w.what == "plan.append") {
            Json kept = progress_json();
            kept["kept"] = true;
            reply(w.id, Status::Ok, {}, std::move(kept));
        } else {
            reply(
                w.id, Status::Failed,
                w.what + ": " + why + "; the board has not done it (it is kept, and done when it is ready)");
        }
    }
}

void PlanController::reply(CommandId id, CommandReply::Status status, std::string error, Json result) {
    replies_.push_back(CommandReply{id, status, std::move(result), std::move(error)});
}

std::optional<ActivePlan> PlanController::prepare_load(CommandId id, LoadRequest in) {
    const char* what = in.append ? "plan.append" : "plan.load";
    if (in.append && !active_) {
        reply(id, Status::Refused, "no plan to append to (use plan.load)");
        return std::nullopt;
    }
    if (in.append && returning_home_) {
        reply(id, Status::Refused, "the vehicle is returning home; load a plan instead");
        return std::nullopt;
    }
    // The new text on its own first, so that its errors carry its own file:line.
    auto loaded = load_plan_text(in.text, in.source, config_.load);
    if (!loaded.ok()) {
        log(Level::Warn,
            fmt::format("{} {} rejected: {}", what, in.source, loaded.errors.front().to_string()));
        reply(id, Status::BadRequest, "plan rejected, nothing changed:\n" + to_string(loaded.errors));
        return std::nullopt;
    }
    ActivePlan plan;
    if (in.append) {
        auto merged = append_plan_text(active_->text, in.text);
        if (!merged.text) {
            reply(id, Status::BadRequest, "plan rejected, nothing changed: " + merged.error);
            return std::nullopt;
        }
        auto combined = load_plan_text(*merged.text, active_->source + " + " + in.source, config_.load);
        if (!combined.ok()) {
            reply(id, Status::BadRequest,
                  "plan rejected, nothing changed: " + in.source + " appended to " + active_->source +
                      " does not validate:\n" + to_string(combined.errors));
            return std::nullopt;
        }
        if (active_->stream) {
            // The merged plan must continue exactly where the running stream stands.
            Expander probe(combined.plan);
            if (!probe.restore(active_->stream->origin(), active_->stream->position())) {
                reply(id, Status::Failed,
                      "plan.append: the merged plan cannot continue where the running one stands; nothing "
                      "changed");
                return std::nullopt;
            }
        }
        plan.plan = combined.plan;
        plan.text = std::move(*merged.text);
        plan.source = active_->source + " + " + in.source;
    } else {
        plan.plan = loaded.plan;
        plan.text = std::move(in.text);
        plan.source = in.source;
    }
    plan.digest = hex64(fnv1a64(plan.text));
    return plan;
}

void PlanController::load(CommandId id, ActivePlan plan, bool append, bool start_paused,
                          const std::string& from, TimePoint now) {
    log(Level::Info, fmt::format("{} '{}' from {}{}", append ? "appended to plan" : "plan", plan.plan->name,
                                 from, start_paused ? ", paused" : ""));
    if (!append) {
        // A loaded plan is there to be driven, whatever the vehicle did before (parked, a finished plan, a
        // paused one), unless the operator asked for it to wait.
        if (start_paused) {
            feeder_.pause();
        } else {
            feeder_.resume();
        }
    }
    start_plan(std::move(plan), append, now);
    wait_for_autopilot(id, append ? "plan.append" : "plan.load", now);
}

void PlanController::skip(CommandId id, std::variant<std::uint64_t, std::string> target, TimePoint now) {
    if (!active_ || !active_->stream) {
        reply(id, Status::Refused, "no plan running");
        return;
    }
    if (const auto* n = std::get_if<std::uint64_t>(&target)) {
        if (!feeder_.skip_to(*n, now)) {
            reply(id, Status::BadRequest,
                  "the plan has no waypoint " + std::to_string(*n) + " from where it stands");
            return;
        }
    } else {
        const auto& name = std::get<std::string>(target);
        if (!feeder_.jump_to(name, now)) {
            reply(id, Status::BadRequest, "the plan has no element named '" + excerpt(name) + "'");
            return;
        }
    }
    wait_for_autopilot(id, "plan.skip", now);
}

void PlanController::pause(CommandId id, TimePoint now) {
    if (!active_ && feeder_.progress().state == PlanState::None) {
        reply(id, Status::Refused, "no plan running");
        return;
    }
    feeder_.pause();
    wait_for_autopilot(id, "plan.pause", now);
}

void PlanController::resume_plan(CommandId id, TimePoint now) {
    if (feeder_.progress().state == PlanState::None) {
        reply(id, Status::Refused, "no plan running");
        return;
    }
    feeder_.resume();
    feeder_.release_hold(now);  // resume also ends a hold-until-released
    wait_for_autopilot(id, "plan.resume", now);
}

Json PlanController::show() const {
    Json j = progress_json();
    const auto p = feeder_.progress();
    j["source"] = active_ ? Json(active_->source) : Json(nullptr);
    j["generation"] = p.generation;
    j["starvation_holds"] = p.starvation_holds;
    j["ignored_reached"] = p.ignored_reached;
    j["retries"] = p.retries;
    j["failures"] = p.failures;
    if (active_) {
        const Plan& plan = *active_->plan;
        auto& elements = j["elements"] = Json::array();
        for (auto id : plan.children(plan.main_list)) {
            const Node& n = plan.nodes[id];
            elements.push_back({{"path", plan.element_path(id)},
                                {"kind", to_string(n.kind)},
                                {"name", plan.element_name(id)},
                                {"line", n.mark.line},
                                {"waypoints", optional_json(plan.count(id))}});
        }
    }
    return j;
}

namespace {

Json lat_lon_json(LatLon p) {
    // 1e-7 degrees is about 1 cm: enough for a map, and the numbers print short.
    return Json::array({std::round(p.lat * 1e7) / 1e7, std::round(p.lon * 1e7) / 1e7});
}

/// Walks a plan's element tree for plan.geometry, spending a budget of points.
class GeometryWalk {
  public:
    GeometryWalk(std::shared_ptr<const Plan> plan, std::size_t max_points)
        : plan_(*plan), stream_(std::move(plan), false), left_(max_points) {}

    void walk(std::uint32_t container, Json& out) {
        for (auto id : plan_.children(container)) {
            const Node& n = plan_.nodes[id];
            switch (n.kind) {
                case NodeKind::Repeat:
                case NodeKind::Block:
                case NodeKind::ElementList:
                    walk(id, out);
                    break;
                case NodeKind::Waypoint:
                case NodeKind::Hold:
                case NodeKind::Scan:
                case NodeKind::Orbit:
                    out.push_back(element(id));
                    break;
                case NodeKind::Speed:
                case NodeKind::Goto:
                    break;
            }
        }
    }

    Json zones() {
        Json out = Json::array();
        for (const auto& zone : plan_.no_fly) {
            Json points = Json::array();
            for (const auto& p : zone.polygon) {
                add(points, p);
            }
            out.push_back({{"name", zone.name}, {"points", std::move(points)}});
        }
        return out;
    }

    bool truncated() const { return truncated_; }

  private:
    Json element(std::uint32_t id) {
        const Node& n = plan_.nodes[id];
        const NodeExtra& extra = plan_.extra(id);
        Json e = {{"path", plan_.element_path(id)},
                  {"kind", to_string(n.kind)},
                  {"name", extra.name.empty() ? Json(nullptr) : Json(extra.name)},
                  {"closed", false}};
        Json points = Json::array();
        if (n.kind == NodeKind::Scan && extra.scan) {
            // The area itself; the lines driven across it follow in "lines".
            e["closed"] = true;
            for (const auto& p : extra.scan->polygon()) {
                add(points, plan_.frame.to_geo(p));
            }
            e["lines"] = waypoints_of(id);
        } else if (n.kind == NodeKind::Hold && !n.has_position) {
            if (last_) {
                add(points, *last_);  // it holds where the previous waypoint ends
            }
        } else {
            points = waypoints_of(id);
        }
        if (n.kind == NodeKind::Hold) {
            e["hold_s"] = extra.hold_seconds ? Json(*extra.hold_seconds) : Json(nullptr);
        }
        e["points"] = std::move(points);
        return e;
    }

    /// The element's waypoints as the expander produces them (scan lines, orbit points).
    Json waypoints_of(std::uint32_t id) {
        Json points = Json::array();
        if (left_ == 0 || !stream_.jump_to_node(id)) {
            truncated_ = truncated_ || left_ == 0;
            return points;
        }
        while (auto w = stream_.next()) {
            if (w->element != id) {
                break;
            }
            if (w->has_position) {
                if (!add(points, w->position)) {
                    break;
                }
                last_ = w->position;
            }
            if (w->last_of_element) {
                break;
            }
        }
        return points;
    }

    bool add(Json& points, LatLon p) {
        if (left_ == 0) {
            truncated_ = true;
            return false;
        }
        --left_;
        points.push_back(lat_lon_json(p));
        return true;
    }

    const Plan& plan_;
    Expander stream_;
    std::size_t left_;
    bool truncated_ = false;
    std::optional<LatLon> last_;
};

}  // namespace

Json PlanController::geometry(std::size_t max_points) const {
    Json j = {
        {"name", nullptr}, {"elements", Json::array()}, {"no_fly", Json::array()}, {"truncated", false}};
    if (!active_ || !active_->plan) {
        return j;
    }
    const auto& plan = active_->plan;
    GeometryWalk walk(plan, max_points);
    j["name"] = plan->name;
    j["generation"] = feeder_.progress().generation;
    j["no_fly"] = walk.zones();
    for (auto list : {plan->main_list, plan->blocks_list}) {
        if (list != kNoNode) {
            walk.walk(list, j["elements"]);
        }
    }
    j["truncated"] = walk.truncated();
    return j;
}

Json PlanController::progress_json() const {
    const auto p = feeder_.progress();
    Json j;
    j["state"] = to_string(p.state);
    j["name"] = p.state == PlanState::None ? Json(nullptr) : Json(p.plan_name);
    j["element"] = p.element.empty() ? Json(nullptr) : Json(p.element);
    j["waypoints_reached"] = p.waypoints_reached;
    j["next_waypoint"] = optional_json(p.next_waypoint);
    j["window"] = p.window;
    j["reaction"] = last_reaction_.empty() ? Json(nullptr) : Json(last_reaction_);
    j["interruption"] = shown_interruption(p).empty() ? Json(nullptr) : Json(shown_interruption(p));
    j["error"] = problem_.empty() ? Json(nullptr) : Json(problem_);
    j["held_at_frontier"] = p.held_at_frontier;
    j["held"] = p.held.empty() ? Json(nullptr) : Json(p.held);
    j["held_until_released"] = p.held_until_released;
    j["frontier_stops"] = p.frontier_stops;
    j["frontier_wait_s"] = std::round(std::chrono::duration<double>(p.frontier_wait).count() * 10.0) / 10.0;
    return j;
}

// ---- time and outputs ----------------------------------------------------------------------------------

void PlanController::handle_timeout(TimePoint now) {
    pump(now);
}

TimePoint PlanController::poll_timeout() const {
    TimePoint next = feeder_.poll_timeout();
    if (reactions_) {
        next = std::min(next, reactions_->poll_timeout());
    }
    for (const auto& w : waiters_) {
        next = std::min(next, w.deadline);
    }
    return next;
}

PlanController::StatusKey PlanController::status_key(const FeederProgress& p) const {
    return {p.state,          p.plan_name,
            p.element,        p.waypoints_reached,
            p.next_waypoint,  p.window,
            last_reaction_,   shown_interruption(p),
            problem_,         p.held_at_frontier,
            p.frontier_stops, p.frontier_wait,
            p.held,           p.held_until_released};
}

// The last interruption is news while its plan runs (and kept after the plan continued); a plan that has
// ended is done with it.
const std::string& PlanController::shown_interruption(const FeederProgress& p) {
    static const std::string kNone;
    return p.state == PlanState::Done || p.state == PlanState::None ? kNone : p.interruption;
}

void PlanController::publish_status(bool force) {
    const auto p = feeder_.progress();
    StatusUpdate u{PlanProgress{p.state, top_element_index(p.element), p.next_waypoint.value_or(0),
                                p.waypoints_reached, p.generation, p.plan_name, p.extensions},
                   std::nullopt};
    auto key = status_key(p);
    if (force || key != last_status_) {
        last_status_ = std::move(key);
        u.section = progress_json();
    }
    statuses_.push_back(std::move(u));
}

void PlanController::log(LogLine::Level level, std::string text) {
    logs_.push_back(LogLine{level, std::move(text)});
}

std::optional<PlanOutput> PlanController::poll_output() {
    return pop(outputs_);
}

std::optional<CommandReply> PlanController::poll_reply() {
    return pop(replies_);
}

std::optional<ProgressSave> PlanController::poll_save() {
    return pop(saves_);
}

std::optional<StatusUpdate> PlanController::poll_status() {
    return pop(statuses_);
}

std::optional<LogLine> PlanController::poll_log() {
    return pop(logs_);
}

}  // namespace airseg::flightplan
