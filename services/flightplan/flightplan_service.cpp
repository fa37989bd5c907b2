#include "services/flightplan/flightplan_service.hpp"

#include <spdlog/spdlog.h>

#include <sstream>

#include "services/flightplan/home_stream.hpp"
#include "services/flightplan/plan_progress.hpp"
#include "services/flightplan/resume.hpp"
#include "services/groundlink/link_state.hpp"
#include "services/status/status_messages.hpp"

namespace airseg::flightplan {

namespace {

autopilot::MissionItem to_autopilot(const MissionItem& m) {
    autopilot::MissionItem out;
    switch (m.kind) {
        case MissionItem::Kind::Waypoint:
            out.kind = autopilot::MissionItem::Kind::Waypoint;
            break;
        case MissionItem::Kind::Stop:
            out.kind = autopilot::MissionItem::Kind::Stop;
            break;
        case MissionItem::Kind::JumpTo:
            out.kind = autopilot::MissionItem::Kind::JumpTo;
            break;
    }
    out.lat = m.position.lat;
    out.lon = m.position.lon;
    out.alt = m.alt.value_or(0.0);
    if (m.speed > 0.0)
        out.speed = m.speed;
    if (m.arrival_radius > 0.0)
        out.radius = m.arrival_radius;
    out.jump_slot = m.jump_slot;
    return out;
}

std::vector<autopilot::MissionItem> to_autopilot(const std::vector<MissionItem>& items) {
    std::vector<autopilot::MissionItem> out;
    out.reserve(items.size());
    for (const auto& m : items)
        out.push_back(to_autopilot(m));
    return out;
}

}  // namespace

FlightplanService::FlightplanService(ServiceContext& ctx, FlightplanServiceConfig config)
    : Service("flightplan", ctx),
      config_(std::move(config)),
      feeder_(config_.feeder),
      timer_(strand()),
      status_timer_(strand()) {
    if (!config_.state_dir.empty())
        store_.emplace(config_.state_dir, config_.durability);
    register_commands();
}

FlightplanService::~FlightplanService() = default;

void FlightplanService::on_start() {
    running_ = true;
    auto& bus = ctx_.bus;
    subscriptions_.push_back(bus.subscribe<autopilot::AutopilotStatus>(
        strand(), [this](const autopilot::AutopilotStatus& s) { on_autopilot_status(s); }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::Telemetry>(strand(), [this](const autopilot::Telemetry& t) {
            if (t.home)
                autopilot_home_ = t.home;
            if (!reactions_)
                return;
            const TimePoint now = SteadyClock::now();
            if (t.battery_remaining)
                reactions_->on_battery(*t.battery_remaining, now);
            if (t.position)
                reactions_->on_position(LatLon{t.position->lat, t.position->lon}, now);
            pump();
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::WaypointReached>(strand(), [this](const autopilot::WaypointReached& r) {
            feeder_.on_reached(r.seq, SteadyClock::now());
            pump();
        }));
    subscriptions_.push_back(bus.subscribe<autopilot::MissionCurrentChanged>(
        strand(), [this](const autopilot::MissionCurrentChanged& c) {
            feeder_.on_current(c.seq, SteadyClock::now());
            pump();
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::AutopilotRebooted>(strand(), [this](const autopilot::AutopilotRebooted&) {
            feeder_.on_autopilot_rebooted(SteadyClock::now());
            in_flight_.clear();
            pump();
        }));
    subscriptions_.push_back(bus.subscribe<autopilot::ModeChanged>(
        strand(), [this](const autopilot::ModeChanged& m) { on_mode_changed(m); }));
    subscriptions_.push_back(bus.subscribe<autopilot::RequestDone>(
        strand(), [this](const autopilot::RequestDone& d) { on_request_done(d); }));
    subscriptions_.push_back(
        bus.subscribe<groundlink::LinkState>(strand(), [this](const groundlink::LinkState& s) {
            // Link loss means losing a link that was there: a vehicle started without a ground station
            // does not react to its absence.
            groundlink_seen_up_ = groundlink_seen_up_ || s.up;
            groundlink_up_ = s.up;
            if (groundlink_seen_up_ && reactions_) {
                reactions_->on_link(s.up, SteadyClock::now());
                pump();
            }
        }));
    resume_stored_plan(SteadyClock::now());
    set_health(Health::Up);
    pump();
    publish_status(true);
    schedule_status();
}

void FlightplanService::on_stop() {
    running_ = false;
    subscriptions_.clear();
    timer_.cancel();
    status_timer_.cancel();
    fail_waiters("the daemon is stopping");
}

// ---- plans ---------------------------------------------------------------------------------------------

std::optional<std::string> FlightplanService::store_plan(const ActivePlan& plan) {
    if (!store_)
        return std::nullopt;
    if (auto err = store_->save_plan(plan.text, plan.source))
        return err;
    return std::nullopt;
}

void FlightplanService::start_plan(ActivePlan plan, bool append, TimePoint now) {
    auto stream = std::make_unique<Expander>(plan.plan);
    Expander* raw = stream.get();
    if (append && active_ && active_->stream) {
        // The merged plan expands like the running one up to its end: continue from the same place.
        (void)raw->restore(active_->stream->origin(), active_->stream->position());  // probed by cmd_load
        feeder_.continue_with(PlanFeed{std::move(stream), plan.plan->name}, now);
    } else {
        feeder_.replace_plan(PlanFeed{std::move(stream), plan.plan->name}, now);
    }
    plan.stream = raw;
    reactions_ = std::make_unique<ReactionMonitor>(ReactionSettings::from_plan(*plan.plan));
    tell_reactions_the_link(now);
    active_ = std::move(plan);
    returning_home_ = false;
    problem_.clear();
    last_saved_.reset();
    save_progress();
}

void FlightplanService::resume_stored_plan(TimePoint now) {
    if (!store_)
        return;
    auto result = resume_from(store_->load(), config_.load);
    for (const auto& p : result.problems) {
        spdlog::warn("{}{}", kPrefix, p);
        problem_ = p;
    }
    if (!result.resumed)
        return;
    auto& r = *result.resumed;
    if (!r.stream) {
        spdlog::info("{}stored plan '{}' was {}; nothing to resume", kPrefix, r.plan->name,
                     to_string(r.progress.state));
        return;
    }
    ActivePlan plan;
    plan.plan = r.plan;
    plan.text = std::move(r.plan_text);
    plan.source = r.plan->source_file;
    plan.digest = r.digest;
    plan.stream = r.stream.get();
    if (r.progress.state == PlanState::Paused)
        feeder_.pause();
    feeder_.restore_plan(PlanFeed{std::move(r.stream), r.plan->name}, r.progress.waypoints_reached, now);
    reactions_ = std::make_unique<ReactionMonitor>(ReactionSettings::from_plan(*plan.plan));
    tell_reactions_the_link(now);
    spdlog::info("{}resuming plan '{}' ({}) at waypoint {}, {} reached{}", kPrefix, r.plan->name, plan.source,
                 r.progress.next_index, r.progress.waypoints_reached,
                 r.progress.state == PlanState::Paused ? ", paused" : "");
    active_ = std::move(plan);
}

// The link's state comes as a change (LinkState): a new plan's reactions start from the one last heard.
void FlightplanService::tell_reactions_the_link(TimePoint now) {
    if (groundlink_seen_up_ && reactions_)
        reactions_->on_link(groundlink_up_, now);
}

void FlightplanService::save_progress() {
    if (!store_ || !active_ || returning_home_)
        return;
    const FeederProgress p = feeder_.progress();
    if (p.state == PlanState::None)
        return;
    SavedProgress s = SavedProgress::from(p, active_->digest);
    if (p.state != PlanState::Done && !p.resume_index) {
        return;  // between states (nothing queued yet): the last saved point still holds
    }
    if (last_saved_ && *last_saved_ == s)
        return;
    if (auto err = store_->save_progress(s)) {
        if (problem_ != *err)
            spdlog::error("{}cannot save progress: {}", kPrefix, *err);
        problem_ = *err;
        return;
    }
    last_saved_ = s;
}

bool FlightplanService::return_home(TimePoint now) {
    std::optional<LatLon> home;
    if (active_ && active_->plan->home) {
        home = *active_->plan->home;
    } else if (autopilot_home_) {
        home = LatLon{autopilot_home_->lat, autopilot_home_->lon};
    }
    if (!home || !active_)
        return false;
    const auto& v = active_->plan->vehicle;
    // The plan's progress stays saved where it was interrupted (paused), so a restart does not drive on.
    if (store_ && last_saved_) {
        SavedProgress paused = *last_saved_;
        paused.state = PlanState::Paused;
        if (!store_->save_progress(paused))
            last_saved_ = paused;
    }
    feeder_.replace_plan(
        PlanFeed{std::make_unique<HomeStream>(*home, v.commanded_cruise_speed(), v.arrival_radius),
                 active_->plan->name + " (return home)"},
        now);
    active_->stream = nullptr;
    returning_home_ = true;
    return true;
}

void FlightplanService::carry_out(const ReactionTrigger& t, TimePoint now) {
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
            if (what.ends_with("hold"))
                feeder_.pause();
            break;
        case ReactionAction::ReturnHome:
            what = return_home(now) ? "return home" : "return home impossible (no home known); hold";
            if (what.ends_with("hold"))
                feeder_.pause();
            break;
    }
    if (t.cause == ReactionTrigger::Cause::LinkRecovered)
        what = "nothing (the link-loss reaction stays in effect)";
    last_reaction_ = cause + ": " + what + (t.detail.empty() ? "" : " (" + t.detail + ")");
    spdlog::warn("{}reaction {}", kPrefix, last_reaction_);
    ctx_.bus.publish(t);
}

// ---- autopilot side ------------------------------------------------------------------------------------

void FlightplanService::on_autopilot_status(const autopilot::AutopilotStatus& s) {
    if (s.ready == autopilot_ready_)
        return;
    autopilot_ready_ = s.ready;
    const std::pair<unsigned, unsigned> counts{s.reconnects, s.reboots};
    if (!autopilot_ready_) {
        // Lost: the window is kept. A board that only went silent drives on, and the waypoints it reports
        // reached meanwhile still count; a reboot (its own event) or a reopened port makes it unknown.
        fail_waiters("the autopilot is not ready");
        pump();
        return;
    }
    const bool same_board = ready_counts_ && *ready_counts_ == counts;
    ready_counts_ = counts;
    if (same_board) {
        pump();  // back, neither rebooted nor reconnected: it still holds the window
        return;
    }
    // Connected afresh: what the autopilot holds is unknown; the window is uploaded again.
    feeder_.on_autopilot_rebooted(SteadyClock::now());
    in_flight_.clear();
    pump();
}

void FlightplanService::on_mode_changed(const autopilot::ModeChanged& m) {
    using S = autopilot::VehicleState;
    VehicleMode mode = VehicleMode::Unknown;
    switch (m.to) {
        case S::WaypointNavigation:
            mode = VehicleMode::Auto;
            break;
        case S::Parking:
            mode = VehicleMode::Hold;
            break;
        case S::Directed:
        case S::ManualNavigation:
        case S::Manual:
            mode = VehicleMode::Manual;
            break;
        case S::Unknown:
        case S::ConfigureCheck:
            break;
    }
    ModeCause cause = ModeCause::Board;
    if (m.cause == autopilot::ModeChangeCause::Requested) {
        cause = ModeCause::Ours;
    } else if (m.to == S::Directed) {
        cause = ModeCause::RcPilot;  // MANUAL that nobody here asked for: the RC transmitter's switch
    }
    feeder_.on_mode(mode, cause, SteadyClock::now());
    pump();
}

void FlightplanService::on_request_done(const autopilot::RequestDone& done) {
    const auto it = in_flight_.find(done.id);
    if (it == in_flight_.end())
        return;  // another requester's, or forgotten after a reconnect
    const std::uint32_t feeder_id = it->second.feeder_id;
    const TimePoint now = SteadyClock::now();
    spdlog::debug("{}#{} {} in {} ms", kPrefix, feeder_id, autopilot::to_string(done.result),
                  std::chrono::duration_cast<std::chrono::milliseconds>(now - it->second.sent).count());
    in_flight_.erase(it);
    const bool ok = done.result == autopilot::RequestResult::Ok;
    // A mission the autopilot refused (its answer, after the driver's fallbacks) or one it cannot hold is
    // final; anything else (timeouts, a busy or reconnecting autopilot) is asked again.
    const bool refused =
        done.result == autopilot::RequestResult::Refused || done.result == autopilot::RequestResult::Invalid;
    if (ok) {
        fault_.reset();
    } else {
        last_failure_ = std::string(autopilot::to_string(done.kind)) + ": " +
                        autopilot::to_string(done.result) +
                        (done.detail.empty() ? "" : " (" + done.detail + ")");
    }
    feeder_.on_request_result(feeder_id,
                              ok        ? RequestResult::Ok
                              : refused ? RequestResult::Refused
                                        : RequestResult::Failed,
                              now, last_failure_);
    pump();
}

void FlightplanService::send(const FeederRequest& request) {
    autopilot::AutopilotRequest r;
    r.id = next_bus_id_;
    next_bus_id_ = next_bus_id_ >= 0x7FFFFFFFu ? kFirstRequestId : next_bus_id_ + 1;
    std::visit(
        [&](const auto& op) {
            using T = std::decay_t<decltype(op)>;
            if constexpr (std::is_same_v<T, UploadMission>) {
                r.op = autopilot::UploadMission{to_autopilot(op.items)};
            } else if constexpr (std::is_same_v<T, WriteItems>) {
                r.op = autopilot::WriteMissionItems{op.first_slot, to_autopilot(op.items)};
            } else if constexpr (std::is_same_v<T, SetCurrent>) {
                r.op = autopilot::SetMissionCurrent{op.slot};
            } else if constexpr (std::is_same_v<T, HoldVehicle>) {
                r.op = autopilot::RequestStateChange{autopilot::VehicleState::Parking};
            } else {
                r.op = autopilot::RequestStateChange{autopilot::VehicleState::WaypointNavigation};
            }
        },
        request.op);
    spdlog::debug("{}{}", kPrefix, [&] {
        std::ostringstream o;
        o << request;
        return o.str();
    }());
    in_flight_[r.id] = InFlight{request.id, SteadyClock::now()};
    ctx_.bus.publish(std::move(r));
}

void FlightplanService::pump() {
    if (!running_)
        return;
    const TimePoint now = SteadyClock::now();
    if (feeder_.poll_timeout() <= now)
        feeder_.handle_timeout(now);
    if (reactions_) {
        if (reactions_->poll_timeout() <= now)
            reactions_->handle_timeout(now);
        while (auto t = reactions_->poll_trigger())
            carry_out(*t, now);
    }
    if (autopilot_ready_) {
        while (auto r = feeder_.poll_request(now))
            send(*r);
    }
    while (auto e = feeder_.poll_event())
        handle_event(*e);
    save_progress();
    answer_waiters(now);
    publish_status(false);
    arm_timer();
}

void FlightplanService::handle_event(const FeederEvent& e) {
    switch (e.kind) {
        case FeederEvent::Kind::WaypointReached:
            spdlog::debug("{}waypoint {} reached ({})", kPrefix, e.plan_index, e.element_path);
            break;
        case FeederEvent::Kind::ElementStarted:
        case FeederEvent::Kind::ElementFinished:
        case FeederEvent::Kind::HoldStarted:
        case FeederEvent::Kind::HoldEnded:
            spdlog::info("{}{} {}", kPrefix, to_string(e.kind), e.element_path);
            break;
        case FeederEvent::Kind::PlanDone: {
            // A named copy, not a member of a temporary inside a case: clang 14's AddressSanitizer reported
            // the temporary's destruction as a use after its scope (the CI sanitizer stage, heartbeat-stall
            // case).
            const std::string name = feeder_.progress().plan_name;
            spdlog::info("{}plan '{}' done", kPrefix, name);
            break;
        }
        case FeederEvent::Kind::PlanBlocked:
            spdlog::error("{}plan stopped: {}", kPrefix, e.detail);
            problem_ = e.detail;
            break;
        case FeederEvent::Kind::RequestFailed:
            fault_ = last_failure_.empty() ? e.detail : last_failure_;
            spdlog::error("{}autopilot request failed after retries: {}; holding", kPrefix, *fault_);
            fail_waiters("the autopilot did not confirm: " + *fault_);
            break;
        case FeederEvent::Kind::WindowStarved:
            spdlog::warn("{}window starved at waypoint {}: holding until it is written", kPrefix,
                         e.plan_index);
            break;
        case FeederEvent::Kind::Interrupted:
            spdlog::warn("{}plan interrupted at waypoint {}: {}", kPrefix, e.plan_index, e.detail);
            break;
        case FeederEvent::Kind::Continued:
            spdlog::info("{}plan continues at waypoint {} after: {}", kPrefix, e.plan_index, e.detail);
            break;
        case FeederEvent::Kind::PlanFailed:
            spdlog::error("{}plan failed, the vehicle is held: {}", kPrefix, e.detail);
            problem_ = "the autopilot refused the plan: " + e.detail;
            fail_waiters(problem_);
            break;
    }
    ctx_.bus.publish(e);
}

void FlightplanService::answer_waiters(TimePoint now) {
    if (waiters_.empty())
        return;
    if (!autopilot_ready_) {
        fail_waiters("the autopilot is not ready (the plan is kept and starts when it is)");
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
        for (auto& w : done)
            w.reply(CommandResult::ok(progress));
        return;
    }
    std::vector<Waiter> keep;
    for (auto& w : waiters_) {
        if (now >= w.deadline) {
            w.reply(CommandResult::fail(
                CommandStatus::Failed,
                w.what + ": the autopilot did not confirm in time" +
                    (last_failure_.empty() ? "" : " (last failure: " + last_failure_ + ")")));
        } else {
            keep.push_back(std::move(w));
        }
    }
    waiters_ = std::move(keep);
}

void FlightplanService::fail_waiters(const std::string& why) {
    auto failed = std::move(waiters_);
    waiters_.clear();
    for (auto& w : failed)
        w.reply(CommandResult::fail(CommandStatus::Failed, w.what + ": " + why));
}

void FlightplanService::arm_timer() {
    TimePoint next = feeder_.poll_timeout();
    if (reactions_)
        next = std::min(next, reactions_->poll_timeout());
    for (const auto& w : waiters_)
        next = std::min(next, w.deadline);
    timer_.arm(next, [this] {
        if (running_)
            pump();
    });
}

void FlightplanService::schedule_status() {
    // On the grid the services' progress ticks use: one wake-up for both (time.hpp).
    status_timer_.expires_at(next_on_grid(SteadyClock::now(), config_.status_period));
    status_timer_.async_wait([this](const boost::system::error_code& ec) {
        if (ec || !running_)
            return;
        publish_status(true);
        schedule_status();
    });
}

namespace {

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

}  // namespace

void FlightplanService::publish_status(bool force) {
    const auto p = feeder_.progress();
    ctx_.bus.publish_latest(PlanProgress{p.state, top_element_index(p.element), p.next_waypoint.value_or(0),
                                         p.waypoints_reached});
    Json j = progress_json();
    if (!force && j == last_status_)
        return;
    last_status_ = j;
    ctx_.bus.publish(status::StatusSection{"plan", std::move(j), {}});
}

}  // namespace airseg::flightplan
