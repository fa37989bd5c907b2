#include "daemon/autopilot_commands.hpp"

#include <cmath>

#include "daemon/autopilot_status.hpp"

namespace airseg::daemon {

namespace {

using autopilot::RequestResult;

bool valid_param_name(const Json& name) {
    return name.is_string() && !name.get_ref<const std::string&>().empty() &&
           name.get_ref<const std::string&>().size() <= 16;
}

// What an ok reply carries: `result` completed from the autopilot's answer.
Json completed_result(const autopilot::RequestDone& done, Json result) {
    switch (done.kind) {
        case autopilot::RequestKind::GetParam:
        case autopilot::RequestKind::SetParam:
            if (done.param_value) {
                result["value"] = *done.param_value;
            }
            break;
        case autopilot::RequestKind::SetState:
            if (done.armed) {
                result["armed"] = *done.armed;
            }
            break;
        case autopilot::RequestKind::ListParams: {
            auto& params = result["params"] = Json::object();
            for (const auto& [name, value] : done.params) {
                params[name] = value;
            }
            result["count"] = done.params.size();
            break;
        }
        default:
            break;
    }
    return result;
}

}  // namespace

CommandResult command_result(const autopilot::RequestDone& done, Json result) {
    const std::string why = done.detail.empty()
                                ? autopilot::to_string(done.result)
                                : std::string(autopilot::to_string(done.result)) + ": " + done.detail;
    switch (done.result) {
        case RequestResult::Ok:
            return CommandResult::ok(std::move(result));
        case RequestResult::Invalid:
            return CommandResult::fail(CommandStatus::BadRequest, why);
        case RequestResult::Refused:
        case RequestResult::NotReady:
        case RequestResult::Busy:
            return CommandResult::fail(CommandStatus::Refused, why);
        case RequestResult::Timeout:
        case RequestResult::Cancelled:
            break;
    }
    return CommandResult::fail(CommandStatus::Failed, why);
}

AutopilotCommands::AutopilotCommands(Bus& bus, CommandDispatcher& commands, Strand strand)
    : bus_(bus), strand_(strand) {
    commands.add("state", strand_, Role::Control, [this](const Json& req, CommandDispatcher::Reply reply) {
        const auto it = req.find("state");
        const auto state = it != req.end() && it->is_string()
                               ? parse_state_name(it->get_ref<const std::string&>())
                               : std::nullopt;
        if (!state) {
            reply(CommandResult::fail(CommandStatus::BadRequest,
                                      "\"state\" must be one of PARKING, DIRECTED, MANUAL_NAVIGATION, "
                                      "WAYPOINT_NAVIGATION"));
            return;
        }
        request(autopilot::RequestStateChange{*state}, {{"state", state_name(*state)}}, std::move(reply));
    });
    commands.add(
        "param.get", strand_, Role::Monitor, [this](const Json& req, CommandDispatcher::Reply reply) {
            const auto name = req.value("name", Json());
            if (!valid_param_name(name)) {
                reply(CommandResult::fail(CommandStatus::BadRequest,
                                          "\"name\" must be a parameter name (1..16)"));
                return;
            }
            request(autopilot::GetParam{name.get<std::string>()}, {{"name", name}}, std::move(reply));
        });
    commands.add("param.set", strand_, Role::Control,
                 [this](const Json& req, CommandDispatcher::Reply reply) {
                     const auto name = req.value("name", Json());
                     const auto value = req.value("value", Json());
                     if (!valid_param_name(name)) {
                         reply(CommandResult::fail(CommandStatus::BadRequest,
                                                   "\"name\" must be a parameter name (1..16)"));
                         return;
                     }
                     if (!value.is_number() || !std::isfinite(value.get<double>())) {
                         reply(CommandResult::fail(CommandStatus::BadRequest, "\"value\" must be a number"));
                         return;
                     }
                     request(autopilot::SetParam{name.get<std::string>(), value.get<double>()},
                             {{"name", name}}, std::move(reply));
                 });
    add_param_list(commands);
}

void AutopilotCommands::add_param_list(CommandDispatcher& commands) {
    commands.add("param.list", strand_, Role::Monitor, [this](const Json&, CommandDispatcher::Reply reply) {
        request(autopilot::ListParams{}, Json::object(), std::move(reply));
    });
}

void AutopilotCommands::request(Op op, Json result, CommandDispatcher::Reply reply) {
    autopilot::AutopilotRequest r;
    r.op = std::move(op);
    r.reply = Reply<autopilot::RequestDone>(
        strand_, guard_, autopilot::not_answered(),
        [result = std::move(result), reply = std::move(reply)](const autopilot::RequestDone& done) mutable {
            reply(command_result(done, completed_result(done, std::move(result))));
        });
    bus_.publish(std::move(r));
}

}  // namespace airseg::daemon
