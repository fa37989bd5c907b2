// The ground-link service's commands (telemetry rates, joystick) and what it forwards from the bus to the
// ground (vehicle telemetry samples, events and autopilot texts).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "services/flightplan/plan_progress.hpp"
#include "services/groundlink/event_text.hpp"
#include "services/groundlink/groundlink_messages.hpp"
#include "services/groundlink/groundlink_service.hpp"

namespace airseg::groundlink {

namespace {

double rounded(double v) {
    return std::round(v * 1000) / 1000;
}

}  // namespace

nlohmann::json GroundlinkService::rates_json(const RatesSnapshot& rates) {
    const auto& scheduler = rates.scheduler;
    nlohmann::json requested, effective;
    for (auto k : kAllTelemetryKinds) {
        requested[to_string(k)] = rounded(scheduler.requested_hz(k));
        effective[to_string(k)] = rounded(scheduler.effective_hz(k));
    }
    return {{"requested_hz", requested},
            {"effective_hz", effective},
            {"factor", scheduler.factor()},
            {"weak_link", scheduler.weak()},
            {"budget_bytes_per_s", std::round(scheduler.budget_bytes_per_s())},
            {"lowerings", scheduler.lowerings()},
            {"restorations", scheduler.restorations()},
            {"samples_sent", rates.samples_sent},
            {"delivery_loss",
             rates.delivery_loss ? nlohmann::json(rounded(*rates.delivery_loss)) : nlohmann::json()}};
}

void GroundlinkService::register_commands() {
    if (commands_registered_) {
        return;
    }
    commands_registered_ = true;
    ctx_.commands.add("rates", strand(), Role::Monitor, [this](const Json&, CommandDispatcher::Reply reply) {
        reply(CommandResult::ok(rates_json()));
    });
    ctx_.commands.add(
        "rates.set", strand(), Role::Control, [this](const Json& req, CommandDispatcher::Reply reply) {
            const auto it = req.find("rates");
            if (it == req.end() || !it->is_object() || it->empty()) {
                reply(CommandResult::fail(
                    CommandStatus::BadRequest,
                    "\"rates\" must be an object of KIND: HZ (kinds: vehicle, link_stats)"));
                return;
            }
            std::vector<std::pair<TelemetryKind, double>> changes;
            for (const auto& [name, value] : it->items()) {
                const auto kind = telemetry_kind_from_string(name);
                if (!kind) {
                    reply(CommandResult::fail(CommandStatus::BadRequest,
                                              "unknown telemetry kind '" + name + "' (vehicle, link_stats)"));
                    return;
                }
                const double hz = value.is_number() ? value.get<double>() : -1.0;
                if (!(hz >= 0 && hz <= TelemetrySchedulerConfig::kMaxHz)) {
                    reply(CommandResult::fail(CommandStatus::BadRequest,
                                              fmt::format("{}: rate must be a number of Hz in 0..{}", name,
                                                          TelemetrySchedulerConfig::kMaxHz)));
                    return;
                }
                changes.emplace_back(*kind, hz);
            }
            const TimePoint now = SteadyClock::now();
            for (const auto& [kind, hz] : changes) {
                scheduler_.set_rate(kind, hz, now);
            }
            arm_telemetry();
            publish_status();
            reply(CommandResult::ok(rates_json()));
        });
    ctx_.commands.add(
        "joystick", strand(), Role::Control, [this](const Json& req, CommandDispatcher::Reply reply) {
            auto axis = [&req](const char* name) -> std::optional<double> {
                const auto it = req.find(name);
                if (it == req.end()) {
                    return 0.0;
                }
                if (!it->is_number() || !(it->get<double>() >= -1.0 && it->get<double>() <= 1.0)) {
                    return std::nullopt;
                }
                return it->get<double>();
            };
            const auto steering = axis("steering");
            const auto throttle = axis("throttle");
            if (!steering || !throttle) {
                reply(CommandResult::fail(CommandStatus::BadRequest,
                                          "\"steering\" and \"throttle\" must be -1..1"));
                return;
            }
            ++joystick_inputs_;
            ctx_.bus.publish(autopilot::JoystickInput{*steering, *throttle});
            nlohmann::json result{{"steering", *steering}, {"throttle", *throttle}};
            if (vehicle_) {
                result["state"] = protocol::vehicle_state_name(static_cast<std::uint8_t>(vehicle_->state));
            }
            reply(CommandResult::ok(std::move(result)));
        });
}

bool GroundlinkService::plan_driving() const {
    return plan_progress_ && plan_drives_mission(plan_progress_->state);
}

void GroundlinkService::subscribe_bus() {
    auto& bus = ctx_.bus;
    using Sev = protocol::Event::Severity;
    subscriptions_.push_back(bus.subscribe<autopilot::Telemetry>(
        strand(), [this](const autopilot::Telemetry& t) { vehicle_ = t; }));
    if (config_.mavlink_forward.enabled) {
        subscriptions_.push_back(bus.subscribe<autopilot::ForwardedFrame>(
            strand(), [this](const autopilot::ForwardedFrame& f) { on_forwarded(f); }));
    }
    subscriptions_.push_back(
        bus.subscribe<flightplan::PlanProgress>(strand(), [this](const flightplan::PlanProgress& p) {
            if (plan_progress_) {
                if (auto text = plan_reached_text(*plan_progress_, p)) {
                    send_event(Sev::Info, *text);
                }
            }
            if (auto text = plan_announcement_text(announced_plan_, p)) {
                send_event(Sev::Info, *text);
            }
            if (plan_drives_mission(p.state)) {
                announced_plan_ = AnnouncedPlan{p.generation, p.extensions};
            }
            plan_progress_ = p;
            plan_ = PlanProgressSample{
                static_cast<std::uint8_t>(p.state),
                static_cast<std::uint16_t>(std::min<std::uint32_t>(p.element, 16383)),
                static_cast<std::uint32_t>(std::min<std::uint64_t>(p.next_waypoint, 0xFFFFFF))};
        }));
    subscriptions_.push_back(
        bus.subscribe<TelemetryConfigChanged>(strand(), [this](const TelemetryConfigChanged& c) {
            config_.telemetry = c.config;
            scheduler_.set_config(c.config, SteadyClock::now());
            arm_telemetry();
            publish_status();
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::ModeChanged>(strand(), [this](const autopilot::ModeChanged& m) {
            if (auto text = mode_change_event(m)) {
                send_event(Sev::Info, *text);
            }
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::StatusText>(strand(), [this](const autopilot::StatusText& t) {
            if (plan_driving() && is_window_text(t.text)) {
                ++events_folded_;
                return;
            }
            send_event(status_text_severity(t.severity, t.text), "autopilot: " + t.text);
        }));
    subscriptions_.push_back(bus.subscribe<autopilot::LinkUp>(
        strand(), [this](const autopilot::LinkUp&) { send_event(Sev::Info, "autopilot link up"); }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::LinkDown>(strand(), [this](const autopilot::LinkDown& d) {
            send_event(Sev::Error, "autopilot link down: " + d.reason);
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::AutopilotRebooted>(strand(), [this](const autopilot::AutopilotRebooted& r) {
            send_event(Sev::Warning, "autopilot rebooted: " + r.evidence);
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::WaypointReached>(strand(), [this](const autopilot::WaypointReached& w) {
            if (plan_driving()) {
                ++events_folded_;  // a slot of the plan's window: the plan's own event says which waypoint
                return;
            }
            send_event(Sev::Info, fmt::format("mission slot {} reached", w.seq));
        }));
}

}  // namespace airseg::groundlink
