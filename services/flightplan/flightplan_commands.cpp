// The flight plan commands of FlightplanService (see docs/flight-plan.md, "Commands").
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "services/flightplan/flightplan_service.hpp"
#include "services/flightplan/plan_merge.hpp"

namespace airseg::flightplan {

namespace {

struct PlanText {
    std::string text;
    std::string source;
    std::string error;
};

/// The plan text of a request: {"path": FILE} (read on board) or {"text": YAML, "source": NAME}.
PlanText plan_text_of(const Json& req) {
    PlanText out;
    const auto path = req.find("path");
    const auto text = req.find("text");
    if ((path != req.end()) == (text != req.end())) {
        out.error = "give exactly one of \"path\" (a plan file on board) or \"text\" (the plan itself)";
        return out;
    }
    if (text != req.end()) {
        if (!text->is_string()) {
            out.error = "\"text\" must be a string";
            return out;
        }
        out.text = text->get<std::string>();
        const auto source = req.find("source");
        out.source =
            source != req.end() && source->is_string() && !source->get_ref<const std::string&>().empty()
                ? source->get<std::string>()
                : std::string("<inline>");
        if (out.text.size() > kMaxPlanTextBytes)
            out.error = "plan larger than " + std::to_string(kMaxPlanTextBytes) + " bytes";
        return out;
    }
    if (!path->is_string() || path->get_ref<const std::string&>().empty()) {
        out.error = "\"path\" must be a file name";
        return out;
    }
    out.source = path->get<std::string>();
    std::ifstream in(out.source, std::ios::binary);
    if (!in) {
        out.error = out.source + ": cannot open the file";
        return out;
    }
    // Sized to the file: the text is kept with the running plan (persistence, plan.append), and a buffer of
    // the largest allowed plan would stay allocated, and resident, with it.
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    in.clear();
    in.seekg(0, std::ios::beg);
    std::size_t want = size >= 0 ? static_cast<std::size_t>(std::min<std::uint64_t>(
                                       static_cast<std::uint64_t>(size), kMaxPlanTextBytes + 1))
                                 : std::size_t{64} << 10;
    // Not seekable (a pipe): read in growing steps, never more than one byte past the largest plan.
    while (true) {
        const std::size_t have = out.text.size();
        out.text.resize(have + want);
        in.read(out.text.data() + have, static_cast<std::streamsize>(want));
        out.text.resize(have + static_cast<std::size_t>(in.gcount()));
        if (!in || out.text.size() > kMaxPlanTextBytes || in.peek() == std::char_traits<char>::eof())
            break;
        want = std::min(out.text.size(), kMaxPlanTextBytes + 1 - out.text.size());
    }
    out.text.shrink_to_fit();
    if (out.text.size() > kMaxPlanTextBytes)
        out.error = out.source + ": plan larger than " + std::to_string(kMaxPlanTextBytes) + " bytes";
    return out;
}

Json optional_json(const std::optional<std::uint64_t>& v) {
    return v ? Json(*v) : Json(nullptr);
}

}  // namespace

void FlightplanService::register_commands() {
    auto& c = ctx_.commands;
    c.add("plan.load", strand(), Role::Control, [this](const Json& req, CommandDispatcher::Reply reply) {
        cmd_load(req, std::move(reply), false);
    });
    c.add("plan.append", strand(), Role::Control,
          [this](const Json& req, CommandDispatcher::Reply reply) { cmd_load(req, std::move(reply), true); });
    c.add("plan.show", strand(), Role::Monitor,
          [this](const Json&, CommandDispatcher::Reply reply) { cmd_show(std::move(reply)); });
    c.add("plan.skip", strand(), Role::Control,
          [this](const Json& req, CommandDispatcher::Reply reply) { cmd_skip(req, std::move(reply)); });
    c.add("plan.pause", strand(), Role::Control,
          [this](const Json&, CommandDispatcher::Reply reply) { cmd_pause(std::move(reply)); });
    c.add("plan.resume", strand(), Role::Control,
          [this](const Json&, CommandDispatcher::Reply reply) { cmd_resume(std::move(reply)); });
}

void FlightplanService::wait_for_autopilot(std::string what, CommandDispatcher::Reply reply) {
    waiters_.push_back(
        Waiter{std::move(reply), std::move(what), SteadyClock::now() + config_.command_timeout});
    pump();
}

void FlightplanService::cmd_load(const Json& req, CommandDispatcher::Reply reply, bool append) {
    const char* what = append ? "plan.append" : "plan.load";
    auto in = plan_text_of(req);
    if (!in.error.empty()) {
        reply(CommandResult::fail(CommandStatus::BadRequest, in.error));
        return;
    }
    if (append && !active_) {
        reply(CommandResult::fail(CommandStatus::Refused, "no plan to append to (use plan.load)"));
        return;
    }
    if (append && returning_home_) {
        reply(CommandResult::fail(CommandStatus::Refused,
                                  "the vehicle is returning home; load a plan instead"));
        return;
    }
    // The new text on its own first, so that its errors carry its own file:line.
    auto loaded = load_plan_text(in.text, in.source, config_.load);
    if (!loaded.ok()) {
        spdlog::warn("{}{} {} rejected: {}", kPrefix, what, in.source, loaded.errors.front().to_string());
        reply(CommandResult::fail(CommandStatus::BadRequest,
                                  "plan rejected, nothing changed:\n" + to_string(loaded.errors)));
        return;
    }
    ActivePlan plan;
    if (append) {
        auto merged = append_plan_text(active_->text, in.text);
        if (!merged.text) {
            reply(CommandResult::fail(CommandStatus::BadRequest,
                                      "plan rejected, nothing changed: " + merged.error));
            return;
        }
        auto combined = load_plan_text(*merged.text, active_->source + " + " + in.source, config_.load);
        if (!combined.ok()) {
            reply(CommandResult::fail(CommandStatus::BadRequest,
                                      "plan rejected, nothing changed: " + in.source + " appended to " +
                                          active_->source + " does not validate:\n" +
                                          to_string(combined.errors)));
            return;
        }
        if (active_->stream) {
            // The merged plan must continue exactly where the running stream stands.
            Expander probe(combined.plan);
            if (!probe.restore(active_->stream->origin(), active_->stream->position())) {
                reply(
                    CommandResult::fail(CommandStatus::Failed,
                                        "plan.append: the merged plan cannot continue where the running one "
                                        "stands; nothing changed"));
                return;
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
    if (auto err = store_plan(plan)) {
        reply(CommandResult::fail(CommandStatus::Failed, "cannot keep the plan, nothing changed: " + *err));
        return;
    }
    const auto paused = req.find("paused");
    if (paused != req.end() && !paused->is_boolean()) {
        reply(CommandResult::fail(CommandStatus::BadRequest, "\"paused\" must be true or false"));
        return;
    }
    const bool start_paused = paused != req.end() && paused->get<bool>();
    spdlog::info("{}{} '{}' from {}{}", kPrefix, append ? "appended to plan" : "plan", plan.plan->name,
                 in.source, start_paused ? ", paused" : "");
    if (!append) {
        // A loaded plan is there to be driven, whatever the vehicle did before (parked, a finished plan, a
        // paused one), unless the operator asked for it to wait.
        if (start_paused) {
            feeder_.pause();
        } else {
            feeder_.resume();
        }
    }
    start_plan(std::move(plan), append, SteadyClock::now());
    wait_for_autopilot(what, std::move(reply));
}

void FlightplanService::cmd_show(CommandDispatcher::Reply reply) {
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
    reply(CommandResult::ok(std::move(j)));
}

void FlightplanService::cmd_skip(const Json& req, CommandDispatcher::Reply reply) {
    if (!active_ || !active_->stream) {
        reply(CommandResult::fail(CommandStatus::Refused, "no plan running"));
        return;
    }
    const TimePoint now = SteadyClock::now();
    const auto index = req.find("index");
    const auto element = req.find("element");
    if (index != req.end() && index->is_number_unsigned()) {
        const auto n = index->get<std::uint64_t>();
        if (!feeder_.skip_to(n, now)) {
            reply(CommandResult::fail(
                CommandStatus::BadRequest,
                "the plan has no waypoint " + std::to_string(n) + " from where it stands"));
            return;
        }
    } else if (element != req.end() && element->is_string()) {
        const auto& name = element->get_ref<const std::string&>();
        if (!feeder_.jump_to(name, now)) {
            reply(CommandResult::fail(CommandStatus::BadRequest,
                                      "the plan has no element named '" + name + "'"));
            return;
        }
    } else {
        reply(CommandResult::fail(
            CommandStatus::BadRequest,
            "give \"index\" (a waypoint of the expanded plan, >= 0) or \"element\" (a name)"));
        return;
    }
    wait_for_autopilot("plan.skip", std::move(reply));
}

void FlightplanService::cmd_pause(CommandDispatcher::Reply reply) {
    if (!active_ && feeder_.progress().state == PlanState::None) {
        reply(CommandResult::fail(CommandStatus::Refused, "no plan running"));
        return;
    }
    feeder_.pause();
    wait_for_autopilot("plan.pause", std::move(reply));
}

void FlightplanService::cmd_resume(CommandDispatcher::Reply reply) {
    if (feeder_.progress().state == PlanState::None) {
        reply(CommandResult::fail(CommandStatus::Refused, "no plan running"));
        return;
    }
    feeder_.resume();
    feeder_.release_hold(SteadyClock::now());  // resume also ends a hold-until-released
    wait_for_autopilot("plan.resume", std::move(reply));
}

Json FlightplanService::progress_json() const {
    const auto p = feeder_.progress();
    Json j;
    j["state"] = to_string(p.state);
    j["name"] = p.state == PlanState::None ? Json(nullptr) : Json(p.plan_name);
    j["element"] = p.element.empty() ? Json(nullptr) : Json(p.element);
    j["waypoints_reached"] = p.waypoints_reached;
    j["next_waypoint"] = optional_json(p.next_waypoint);
    j["window"] = p.window;
    j["reaction"] = last_reaction_.empty() ? Json(nullptr) : Json(last_reaction_);
    j["interruption"] = p.interruption.empty() ? Json(nullptr) : Json(p.interruption);
    j["error"] = problem_.empty() ? Json(nullptr) : Json(problem_);
    return j;
}

}  // namespace airseg::flightplan
