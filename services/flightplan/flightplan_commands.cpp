// The flight plan commands of FlightplanService (see docs/flight-plan.md, "Commands").
#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

#include "base/file_text.hpp"
#include "services/flightplan/flightplan_service.hpp"
#include "services/flightplan/ground_mission.hpp"

namespace airseg::flightplan {

namespace {

/// The longest "source" or "path" of a plan request (PATH_MAX).
constexpr std::size_t kMaxSourceBytes = 4096;

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
        if (out.source.size() > kMaxSourceBytes) {
            // The source is shown in every status document while the plan runs.
            out.error = "\"source\" longer than the " + std::to_string(kMaxSourceBytes) + " bytes allowed";
            return out;
        }
        if (out.text.size() > kMaxPlanTextBytes) {
            out.error = "plan larger than " + std::to_string(kMaxPlanTextBytes) + " bytes";
        }
        return out;
    }
    if (!path->is_string() || path->get_ref<const std::string&>().empty() ||
        path->get_ref<const std::string&>().size() > kMaxSourceBytes) {
        out.error = "\"path\" must be a file name of at most " + std::to_string(kMaxSourceBytes) + " bytes";
        return out;
    }
    out.source = path->get<std::string>();
    // A FIFO, a device (/dev/zero) or a directory is refused at once: this runs on the service's strand.
    auto file = read_file_text(out.source, kMaxPlanTextBytes);
    if (!file.ok()) {
        out.error = out.source + ": " + file.error;
        return out;
    }
    out.text = std::move(file.text);
    // Sized to the file: the text is kept with the running plan (persistence, plan.append).
    out.text.shrink_to_fit();
    return out;
}

}  // namespace

void FlightplanService::register_commands() {
    auto& c = ctx_.commands;
    c.add("plan.load", strand(), Role::Control, [this](const Json& req, CommandDispatcher::Reply reply) {
        cmd_load(req, std::move(reply), false);
    });
    c.add("plan.append", strand(), Role::Control,
          [this](const Json& req, CommandDispatcher::Reply reply) { cmd_load(req, std::move(reply), true); });
    c.add("plan.show", strand(), Role::Monitor, [this](const Json&, CommandDispatcher::Reply reply) {
        reply(CommandResult::ok(controller_.show()));
    });
    c.add("plan.geometry", strand(), Role::Monitor,
          [this](const Json& req, CommandDispatcher::Reply reply) { cmd_geometry(req, std::move(reply)); });
    c.add("plan.skip", strand(), Role::Control,
          [this](const Json& req, CommandDispatcher::Reply reply) { cmd_skip(req, std::move(reply)); });
    c.add("plan.pause", strand(), Role::Control, [this](const Json&, CommandDispatcher::Reply reply) {
        controller_.pause(keep_reply(std::move(reply)), SteadyClock::now());
        flush();
    });
    c.add("plan.resume", strand(), Role::Control, [this](const Json&, CommandDispatcher::Reply reply) {
        controller_.resume_plan(keep_reply(std::move(reply)), SteadyClock::now());
        flush();
    });
}

CommandId FlightplanService::keep_reply(CommandDispatcher::Reply reply) {
    const CommandId id = next_command_id_++;
    replies_.emplace(id, std::move(reply));
    return id;
}

void FlightplanService::cmd_load(const Json& req, CommandDispatcher::Reply reply, bool append) {
    auto in = plan_text_of(req);
    if (!in.error.empty()) {
        reply(CommandResult::fail(CommandStatus::BadRequest, in.error));
        return;
    }
    const CommandId id = keep_reply(std::move(reply));
    const std::string source = in.source;
    auto plan = controller_.prepare_load(id, LoadRequest{std::move(in.text), in.source, append});
    if (!plan) {
        flush();
        return;
    }
    const auto refuse = [&](CommandStatus status, std::string error) {
        auto it = replies_.find(id);
        auto r = std::move(it->second);
        replies_.erase(it);
        flush();
        r(CommandResult::fail(status, std::move(error)));
    };
    if (store_) {
        if (auto err = store_->save_plan(plan->text, plan->source)) {
            refuse(CommandStatus::Failed, "cannot keep the plan, nothing changed: " + *err);
            return;
        }
    }
    const auto paused = req.find("paused");
    if (paused != req.end() && !paused->is_boolean()) {
        refuse(CommandStatus::BadRequest, "\"paused\" must be true or false");
        return;
    }
    const bool start_paused = paused != req.end() && paused->get<bool>();
    controller_.load(id, std::move(*plan), append, start_paused, source, SteadyClock::now());
    flush();
}

void FlightplanService::on_ground_station_mission(const autopilot::GroundStationMission& m) {
    if (auto refusal = ground_mission_refusal(controller_.progress())) {
        log_.log(std::string(kPrefix) + "a ground station's mission refused", SteadyClock::now(),
                 spdlog::level::info, "{}ground station {}'s mission refused: a plan runs", kPrefix,
                 m.station);
        m.reply({false, std::move(*refusal)});
        return;
    }
    log_.log(std::string(kPrefix) + "loading a ground station's mission", SteadyClock::now(),
             spdlog::level::info, "{}loading ground station {}'s mission ({} items) as the plan", kPrefix,
             m.station, m.items.size());
    Json req = Json::object();
    req["text"] = ground_mission_plan(m.items);
    req["source"] = kGroundMissionSource;
    cmd_load(
        req,
        [reply = m.reply](const CommandResult& r) {
            reply({r.status == CommandStatus::Ok, r.status == CommandStatus::Ok ? "" : "airseg: " + r.error});
        },
        false);
}

void FlightplanService::cmd_geometry(const Json& req, CommandDispatcher::Reply reply) {
    // A map needs the shape, not every waypoint of an endless or huge plan: the answer stays one message.
    constexpr std::uint64_t kDefaultPoints = 2000;
    constexpr std::uint64_t kMostPoints = 20000;
    std::uint64_t max_points = kDefaultPoints;
    if (const auto given = req.find("max_points"); given != req.end()) {
        if (!given->is_number_unsigned() || given->get<std::uint64_t>() < 1 ||
            given->get<std::uint64_t>() > kMostPoints) {
            reply(CommandResult::fail(
                CommandStatus::BadRequest,
                "\"max_points\" must be a whole number from 1 to " + std::to_string(kMostPoints)));
            return;
        }
        max_points = given->get<std::uint64_t>();
    }
    reply(CommandResult::ok(controller_.geometry(static_cast<std::size_t>(max_points))));
}

void FlightplanService::cmd_skip(const Json& req, CommandDispatcher::Reply reply) {
    const auto index = req.find("index");
    const auto element = req.find("element");
    std::variant<std::uint64_t, std::string> target;
    if (index != req.end() && index->is_number_unsigned()) {
        target = index->get<std::uint64_t>();
    } else if (element != req.end() && element->is_string()) {
        target = element->get<std::string>();
    } else if (controller_.active() && controller_.active()->stream) {
        reply(CommandResult::fail(
            CommandStatus::BadRequest,
            "give \"index\" (a waypoint of the expanded plan, >= 0) or \"element\" (a name)"));
        return;
    }
    controller_.skip(keep_reply(std::move(reply)), std::move(target), SteadyClock::now());
    flush();
}

}  // namespace airseg::flightplan
